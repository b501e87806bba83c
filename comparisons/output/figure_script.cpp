#include "comparisons/output/figure_script.h"

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include "comparisons/output/backend_style.h"

extern char** environ;

namespace rbx {

int run_figure_script(const std::string& script, const std::vector<std::string>& args,
                      const std::string& log, std::string* why) {
  const std::string python = "/usr/bin/python3";
  const std::string path = std::string(RBX_DEFAULT_SOURCE_DIR) + "/comparisons/output/" + script;
  auto fail = [&](const std::string& reason) {
    if (why) *why = reason;
    return -1;
  };
  if (access(python.c_str(), X_OK) != 0) return fail(python + " not found");
  std::vector<std::string> words = {python, path};
  words.insert(words.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (std::string& w : words) argv.push_back(w.data());
  argv.push_back(nullptr);
  // The script's output goes to the log (fd 1), its errors with it (fd 2).
  posix_spawn_file_actions_t files;
  posix_spawn_file_actions_init(&files);
  posix_spawn_file_actions_addopen(&files, 1, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_adddup2(&files, 1, 2);
  // The backends' colours and markers come from the registry, through the environment.
  std::vector<std::string> env_words = {"RBX_BACKEND_STYLE=" + backend_style_json()};
  for (char** e = environ; *e; ++e)
    if (std::strncmp(*e, "RBX_BACKEND_STYLE=", 18) != 0) env_words.emplace_back(*e);
  std::vector<char*> env;
  for (std::string& w : env_words) env.push_back(w.data());
  env.push_back(nullptr);
  pid_t pid = 0;
  const int rc = posix_spawn(&pid, python.c_str(), &files, nullptr, argv.data(), env.data());
  posix_spawn_file_actions_destroy(&files);
  if (rc != 0) return fail("cannot start " + python + ": " + std::strerror(rc));
  int status = 0;
  while (waitpid(pid, &status, 0) < 0)
    if (errno != EINTR) return fail("lost " + python + ": " + std::strerror(errno));
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

}  // namespace rbx
