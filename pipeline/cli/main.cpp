// sylva: the command line. The table of commands and what runs it (`--help`, `--version`, the exit codes)
// are in command_line.cpp; each command is one file (cmd_NAME.cpp); what they compute lives in
// pipeline/services and the other pipeline folders.
#include <string>
#include <vector>

#include "pipeline/cli/commands.h"

int main(int argc, char** argv)
{
    return sylva::cli::runCommandLine(sylva::cli::commandTable(), std::vector<std::string>(argv + 1, argv + argc));
}
