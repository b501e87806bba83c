// The `rbx` executable.
#include "comparisons/cli/commands.h"

int main(int argc, char** argv) { return rbx::command_line(argc, argv); }
