// The 3-D replay page (`rbx view`): scene text is escaped, and in headless Chromium the page
// loads every backend with its frames, draws the bodies and moves them; a deliberately broken
// page (no bodies, a backend missing) fails the same check.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include "comparisons/eval/harness.h"
#include "comparisons/output/scorecard.h"
#include "comparisons/output/view_page.h"
#include "comparisons/scene/scene_file.h"
#include "engine/format.h"
#include "tests/common/fixtures.h"

namespace fs = std::filesystem;

namespace rbx {
namespace {

using test::temp_dir;

std::string read_file(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// Runs a shell command, returns its exit code.
int shell(const std::string& cmd) {
  const int status = std::system(cmd.c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

bool have_chromium() { return shell("command -v chromium > /dev/null 2>&1") == 0; }

// Headless Chromium with software WebGL (no GPU on a build machine). Running as root needs
// --no-sandbox. The virtual time budget lets the page's timers and animation frames run.
std::string chromium(const std::string& extra, int budget_ms) {
  return "chromium --headless --no-sandbox --disable-gpu --enable-unsafe-swiftshader "
         "--use-angle=swiftshader --hide-scrollbars --window-size=900,800 --virtual-time-budget=" +
         std::to_string(budget_ms) + " " + extra;
}

// The page's own state (#rbx-state) after it loaded and, with `#play`, played for a while.
nlohmann::json page_state(const fs::path& page, const std::string& hash, int budget_ms) {
  const fs::path dom = page.string() + ".dom";
  shell(chromium("--dump-dom 'file://" + page.string() + hash + "'", budget_ms) + " > '" +
        dom.string() + "' 2>/dev/null");
  const std::string html = read_file(dom);
  const std::string open = "<pre id=\"rbx-state\">";
  const size_t a = html.find(open);
  if (a == std::string::npos) return nlohmann::json();
  const size_t b = html.find("</pre>", a);
  std::string text = html.substr(a + open.size(), b - a - open.size());
  // --dump-dom serialises the text with &quot; etc. only for attributes; & < > are escaped.
  for (const auto& [from, to] : std::vector<std::pair<std::string, std::string>>{
           {"&quot;", "\""}, {"&lt;", "<"}, {"&gt;", ">"}, {"&amp;", "&"}}) {
    for (size_t k = text.find(from); k != std::string::npos; k = text.find(from, k + 1))
      text.replace(k, from.size(), to);
  }
  return nlohmann::json::parse(text, nullptr, false);
}

// Coloured pixels (bodies: saturated Okabe-Ito colours, against grey/white panels and black
// text) below `top` in one screenshot, and pixels that differ between two screenshots there.
// Debian's Python with PIL reads the PNGs (python3-pil, installed by ./rbx).
std::pair<long, long> screenshot_pixels(const fs::path& a, const fs::path& b, int top) {
  const fs::path out = a.string() + ".px";
  const std::string py =
      "import sys\nfrom PIL import Image\n"
      "a=Image.open(sys.argv[1]).convert('RGB'); b=Image.open(sys.argv[2]).convert('RGB')\n"
      "top=int(sys.argv[3]); w,h=a.size\n"
      "pa=a.load(); pb=b.load(); col=0; diff=0\n"
      "for y in range(top,h):\n"
      "  for x in range(w):\n"
      "    p=pa[x,y]; q=pb[x,y]\n"
      "    if max(p)-min(p)>40: col+=1\n"
      "    if max(abs(p[i]-q[i]) for i in range(3))>30: diff+=1\n"
      "print(col, diff)\n";
  const fs::path script = a.string() + ".py";
  std::ofstream(script) << py;
  if (shell("/usr/bin/python3 '" + script.string() + "' '" + a.string() + "' '" + b.string() +
            "' " + std::to_string(top) + " > '" + out.string() + "' 2>&1") != 0)
    return {-1, -1};
  std::istringstream in(read_file(out));
  long col = -1, diff = -1;
  in >> col >> diff;
  return {col, diff};
}

// The shortest text that reads back as `v` (a page address's #t=).
std::string fmt_shortest(double v) {
  NumberFormat f;
  f.digits = 0;
  return format_number(v, f);
}

// Everything wrong with a page, judged against `expected` (the view data it should show).
std::vector<std::string> check_page(const fs::path& page, const nlohmann::json& expected) {
  std::vector<std::string> bad;
  // Played from the start for 2 s of virtual time (the page plays a run in 4 s).
  const nlohmann::json st = page_state(page, "#play", 2000);
  if (st.is_discarded() || !st.is_object()) return {"no page state (the script did not run)"};
  if (!st.value("loaded", false))
    bad.push_back("page did not finish loading: " + st.value("error", ""));
  if (!st.value("webgl", false)) bad.push_back("no WebGL renderer");
  for (const auto& [name, b] : expected["backends"].items()) {
    const size_t frames = b["time"].size();
    if (!st["backends"].contains(name))
      bad.push_back("backend " + name + " not loaded");
    else if (st["backends"][name].value("frames", 0ul) != frames)
      bad.push_back("backend " + name + ": " + st["backends"][name]["frames"].dump() +
                    " frames loaded, " + std::to_string(frames) + " expected");
  }
  // A measured ghost (real tosses): loaded with every sample of every body it tracks.
  if (expected.contains("ghost")) {
    const nlohmann::json& g = expected["ghost"];
    if (!st.contains("ghost") || !st["ghost"].is_object())
      bad.push_back("ghost not loaded");
    else if (st["ghost"].value("frames", 0ul) != g["time"].size() ||
             st["ghost"].value("bodies", 0ul) != g["frames"].size() || g["time"].empty())
      bad.push_back("ghost: " + st["ghost"].dump() + ", expected " +
                    std::to_string(g["time"].size()) + " frames of " +
                    std::to_string(g["frames"].size()) + " bodies");
  }
  const size_t bodies = expected["bodies"].size() * expected["backends"].size();
  if (st.value("bodies_drawn", 0ul) != bodies || bodies == 0)
    bad.push_back("bodies drawn: " + st["bodies_drawn"].dump() + ", expected " +
                  std::to_string(bodies) + " (one per body and backend, at least one)");
  if (expected["duration"].get<double>() > 0 && !(st.value("time", 0.0) > 0))
    bad.push_back("playing did not advance the time");
  // #t=SECONDS opens at that time of the run, as a media fragment does (a quarter of it here).
  const std::string quarter = fmt_shortest(expected["duration"].get<double>() / 4);
  const double opened = page_state(page, "#t=" + quarter, 1000).value("time", -1.0);
  if (!(std::abs(opened - std::stod(quarter)) <= 1e-12))
    bad.push_back("#t=" + quarter + " opened at t = " + std::to_string(opened));
  // Screenshots at the start and at the end of the run: bodies drawn, and moved.
  const fs::path s0 = page.string() + ".0.png", s1 = page.string() + ".1.png";
  for (const auto& [shot, hash] : {std::pair{s0, "#t=0"}, std::pair{s1, "#t=end"}})
    shell(chromium("--screenshot='" + shot.string() + "' 'file://" + page.string() + hash + "'",
                   2000) +
          " > /dev/null 2>&1");
  const auto [coloured, moved] = screenshot_pixels(s0, s1, st.value("canvas_top", 0));
  // A body covers thousands of pixels of a 900x800 window; an empty scene none.
  if (coloured < 500)
    bad.push_back("bodies not visible in the screenshot (" + std::to_string(coloured) +
                  " coloured pixels)");
  // A 1 m cube moving 1.25 m in a panel changes thousands of pixels.
  if (moved < 200)
    bad.push_back("bodies did not move between t = 0 and the end (" + std::to_string(moved) +
                  " pixels differ)");
  return bad;
}

// Evaluates a scene (no dt study) and returns its view data.
ViewData data_of(const std::string& file) {
  const Scene scene = load_scene(std::string(RBX_SOURCE_DIR) + "/" + file);
  HarnessOptions opt;
  opt.studies = false;
  opt.timing_budget_s = 0.0;  // the replay only: no run is timed again
  return view_data(scene, read_replay(evaluate_scene(scene, opt).json, kViewMaxEvents));
}

std::string three_js() { return read_file(three_js_path()); }

TEST(ViewPage, SceneTextIsEscapedInHtmlAndJsonAndMarkdown) {
  const fs::path dir = temp_dir("escape");
  const std::string evil = "</script><img src=x onerror=alert(1)> & \"'";
  std::ofstream(dir / "evil.toml")
      << "name = \""
      << "</script><img src=x onerror=alert(1)> & \\\"'"
      << "\"\ndescription = \"<b>bold</b>\"\nchecks = [\"contact\"]\n"
         "backends = [\"exact\"]\n[[body]]\nname = \"A\"\nshape = \"box\"\n"
         "[[body]]\nname = \"B</script>\"\nshape = \"box\"\nposition = [0.9, 0, 0]\n";
  const Scene scene = load_scene((dir / "evil.toml").string());
  ASSERT_EQ(scene.name, evil);
  HarnessOptions opt;
  opt.studies = false;
  opt.timing_budget_s = 0.0;  // the replay only: no run is timed again
  const std::string page = view_page(
      view_data(scene, read_replay(evaluate_scene(scene, opt).json, kViewMaxEvents)), "/*three*/");
  // The only </script> closings are the page's own script elements.
  size_t closings = 0;
  for (size_t k = page.find("</script>"); k != std::string::npos; k = page.find("</script>", k + 1))
    ++closings;
  EXPECT_EQ(closings, 3u);  // three.js, the data, the page script
  EXPECT_EQ(page.find("<img"), std::string::npos);
  EXPECT_EQ(page.find("<b>bold"), std::string::npos);
  EXPECT_NE(page.find("&lt;/script&gt;&lt;img"), std::string::npos);
  EXPECT_EQ(html_escape("<a href=\"x\">&'"), "&lt;a href=&quot;x&quot;&gt;&amp;&#39;");
  EXPECT_EQ(md_escape("a|b[c](d)*_`<x>#"), "a\\|b\\[c\\](d)\\*\\_\\`\\<x\\>\\#");
  fs::remove_all(dir);
}

// The page reads a scene's runs typed (read_replay): every event counted, the first ones kept, a
// number the result wrote as null (a non-finite one) read as NaN and drawn as null again, a run
// without a trajectory read as no frames.
TEST(ViewPage, RunsAreReadTypedOnceAndTheirEventsCut) {
  nlohmann::ordered_json result = {{"backends", nlohmann::ordered_json::object()}};
  nlohmann::ordered_json contacts = nlohmann::ordered_json::array();
  for (int k = 0; k < 5; ++k)
    contacts.push_back({{"bodies", {"A", "B"}},
                        {"time", 0.1 * k},
                        {"point", {k, nullptr, 0.0}},
                        {"normal", {0.0, 0.0, 1.0}},
                        {"depth", 1e-3}});
  result["backends"]["ode"] = {
      {"status", "ok"},
      {"message", ""},
      {"trajectory",
       {{"time", {0.0, 0.5}}, {"bodies", {{"A", {{1, 2, 3, 1, 0, 0, 0}, {4, 5, 6, 1, 0, 0, 0}}}}}}},
      {"contacts", contacts}};
  result["backends"]["exact"] = {{"status", "error"}, {"message", "no hull"}};
  const Replay r = read_replay(result, 3);
  ASSERT_EQ(r.runs.size(), 2u);
  const ReplayRun& ode = r.runs[0];
  EXPECT_EQ(ode.backend, "ode");
  EXPECT_EQ(ode.events_total, 5u);
  ASSERT_EQ(ode.events.size(), 3u);
  EXPECT_EQ(ode.events[2].point.x(), 2.0);
  EXPECT_TRUE(std::isnan(ode.events[2].point.y()));
  EXPECT_EQ(ode.events[2].body_b, "B");
  ASSERT_EQ(ode.motion.tracks.size(), 1u);
  EXPECT_EQ(ode.motion.tracks[0].poses[1][2], 6.0);
  const ReplayRun* exact = r.run_of("exact");
  ASSERT_NE(exact, nullptr);
  EXPECT_EQ(exact->message, "no hull");
  EXPECT_TRUE(exact->motion.time.empty());
  EXPECT_EQ(exact->events_total, 0u);
  EXPECT_EQ(r.run_of("bullet"), nullptr);
  // Drawn: the first events, the count of all, the null kept null.
  Scene scene = load_scene(std::string(RBX_SOURCE_DIR) + "/scenes/analytic/headon_e05.toml");
  const ViewData d = view_data(scene, r);
  const nlohmann::ordered_json& v = d.script["backends"]["ode"];
  EXPECT_EQ(v["events"].size(), 3u);
  EXPECT_EQ(v["events_total"], 5);
  EXPECT_EQ(v["events"][2]["point"].dump(), "[2.0,null,0.0]");  // NaN is written as null
  EXPECT_EQ(v["frames"]["A"][1][0], 4.0);
}

TEST(ViewPage, TrajectoriesAreSampledSoAPageStaysSmall) {
  // 100 bodies: the frame budget keeps the page under 2 MB with three.js inlined (the
  // report's pages of every scene, many_1000 included, are measured in the report).
  const ViewData d = data_of("scenes/many/many_100.toml");
  const std::string page = view_page(d, three_js());
  EXPECT_LT(page.size(), 2u << 20);
  for (const auto& [name, b] : d.script["backends"].items()) {
    EXPECT_GE(b["time"].size(), 2u) << name;
    EXPECT_LE(b["time"].size(), 100u) << name;
  }
}

class ViewBrowser : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!have_chromium())
      GTEST_SKIP() << "chromium not installed (./rbx installs it): browser test skipped";
  }
};

TEST_F(ViewBrowser, PlaysEveryBackendAndTheBodiesAreDrawnAndMove) {
  const fs::path dir = temp_dir("browser");
  const ViewData d = data_of("scenes/analytic/headon_e05.toml");
  ASSERT_GE(d.script["backends"].size(), 2u);
  const fs::path page = dir / "headon_e05.html";
  std::ofstream(page) << view_page(d, three_js());
  const std::vector<std::string> bad = check_page(page, d.script);
  for (const std::string& b : bad) ADD_FAILURE() << b;
  fs::remove_all(dir);
}

// A measured toss replayed by two backends with the measurement as the ghost; and the same page
// with the ghost's samples cut short must fail the check.
TEST_F(ViewBrowser, TossReplayShowsTheMeasuredGhost) {
  const fs::path dir = temp_dir("toss");
  const std::vector<Toss> tosses =
      read_tosses(std::string(RBX_SOURCE_DIR) + "/scenes/real/cube_toss/test.csv.gz");
  ASSERT_FALSE(tosses.empty());
  const Toss& toss = tosses.front();
  std::vector<std::pair<std::string, TossRun>> runs;
  for (const char* name : {"custom", "bullet"})
    runs.emplace_back(name, simulate_toss(find_backend(name)->dynamics, toss, kPublishedParams));
  const ViewData d = toss_replay_data(toss, runs, "toss");
  ASSERT_EQ(d.script["ghost"]["time"].size(), toss.samples.size());
  for (const auto& [name, b] : d.script["backends"].items())
    EXPECT_EQ(b["time"].size(), toss.samples.size()) << name;  // a pose at every measured sample
  std::ofstream(dir / "toss.html") << view_page(d, three_js());
  const std::vector<std::string> bad = check_page(dir / "toss.html", d.script);
  for (const std::string& b : bad) ADD_FAILURE() << b;
  ViewData cut = d;
  cut.script["ghost"]["time"].erase(cut.script["ghost"]["time"].begin());
  std::ofstream(dir / "cut.html") << view_page(cut, three_js());
  const std::vector<std::string> bad_cut = check_page(dir / "cut.html", d.script);
  ASSERT_FALSE(bad_cut.empty());
  EXPECT_EQ(bad_cut.front().rfind("ghost:", 0), 0u) << bad_cut.front();
  fs::remove_all(dir);
}

// A 0.1 m cube dropping onto a static 20 m floor: the camera frames the cube's fall (the moving
// body, its trajectory and contacts), not the floor, so the cube is not a few pixels wide.
TEST_F(ViewBrowser, TheCameraFramesTheMovingBodiesNotTheFloor) {
  const fs::path dir = temp_dir("framing");
  std::ofstream(dir / "drop.toml")
      << "checks = [\"trajectory\"]\nbackends = [\"custom\"]\n[sim]\nduration = 0.3\n"
         "dt = 0.001\n[[body]]\nname = \"floor\"\nshape = \"box\"\nsize = [20, 20, 1]\n"
         "static = true\nposition = [0, 0, -0.5]\n[[body]]\nname = \"cube\"\nshape = \"box\"\n"
         "size = [0.1, 0.1, 0.1]\nposition = [0, 0, 0.2]\n";
  const Scene scene = load_scene((dir / "drop.toml").string());
  HarnessOptions opt;
  opt.studies = false;
  opt.timing_budget_s = 0.0;  // the replay only: no run is timed again
  std::ofstream(dir / "drop.html") << view_page(
      view_data(scene, read_replay(evaluate_scene(scene, opt).json, kViewMaxEvents)), three_js());
  const nlohmann::json st = page_state(dir / "drop.html", "", 2000);
  ASSERT_TRUE(st.is_object() && st.contains("framed")) << st.dump();
  // The cube's fall spans about 0.3 m (from z = 0.25 to the floor at 0); the floor is 20 m.
  const double size = st["framed"]["size"].get<double>();
  EXPECT_GT(size, 0.1);
  EXPECT_LT(size, 1.0);
  fs::remove_all(dir);
}

TEST_F(ViewBrowser, FailsOnABrokenPage) {
  const fs::path dir = temp_dir("broken");
  const ViewData d = data_of("scenes/analytic/headon_e05.toml");
  // A page that lost a backend: judged against the data it should show.
  ViewData missing = d;
  const std::string dropped = missing.script["backends"].begin().key();
  missing.script["backends"].erase(dropped);
  std::ofstream(dir / "missing.html") << view_page(missing, three_js());
  const std::vector<std::string> bad1 = check_page(dir / "missing.html", d.script);
  for (const std::string& b : bad1) std::cout << "missing-backend page: " << b << "\n";
  ASSERT_FALSE(bad1.empty());
  EXPECT_NE(bad1.front().find("backend " + dropped + " not loaded"), std::string::npos)
      << bad1.front();
  // An empty scene: no bodies, so nothing drawn and nothing moves.
  ViewData empty = d;
  empty.script["bodies"] = nlohmann::json::array();
  empty.script["shapes"] = nlohmann::json::array();
  std::ofstream(dir / "empty.html") << view_page(empty, three_js());
  const std::vector<std::string> bad2 = check_page(dir / "empty.html", d.script);
  for (const std::string& b : bad2) std::cout << "empty-scene page: " << b << "\n";
  bool saw_bodies = false, saw_pixels = false;
  for (const std::string& b : bad2) {
    saw_bodies = saw_bodies || b.rfind("bodies drawn", 0) == 0;
    saw_pixels = saw_pixels || b.rfind("bodies not visible", 0) == 0;
  }
  EXPECT_TRUE(saw_bodies);
  EXPECT_TRUE(saw_pixels);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace rbx

namespace rbx {
namespace {

TEST_F(ViewBrowser, WithoutWebGLThePageSaysWhyOnTheScreen) {
  // Chromium with WebGL turned off (--disable-3d-apis): the page cannot draw, and says so in
  // visible text, not only in its hidden state.
  const fs::path dir = temp_dir("no_webgl");
  const ViewData d = data_of("scenes/analytic/headon_e05.toml");
  const fs::path page = dir / "page.html", dom = dir / "page.dom";
  std::ofstream(page) << view_page(d, three_js());
  shell(chromium("--disable-3d-apis --dump-dom 'file://" + page.string() + "'", 1000) + " > '" +
        dom.string() + "' 2>/dev/null");
  const std::string html = read_file(dom);
  ASSERT_NE(html.find("rbx-state"), std::string::npos) << "the page was not dumped";
  const size_t note = html.find("id=\"rbx-no-webgl\"");
  ASSERT_NE(note, std::string::npos) << "no visible notice";
  EXPECT_NE(html.find("did not provide", note), std::string::npos);
  EXPECT_NE(html.find("WebGL unavailable"), std::string::npos);  // the state says why too
  fs::remove_all(dir);
}

}  // namespace
}  // namespace rbx
