// The man page and the bash completion of `sylva`, generated from its command table (commandTable
// in command_line.cpp, and each Command's options), so they never drift from what the program accepts.
// `sylva --man` and `sylva --completion` print them; the build installs their output.
#pragma once

#include <string>
#include <vector>

#include "pipeline/cli/args.h"

namespace sylva::cli {

// sylva(1) in man(7) roff: every command with its synopsis, summary and options.
std::string manPage(const std::vector<Command>& commands);

// A bash completion script (complete -F _sylva sylva): commands, each command's options (-o for
// --output), the words of a value placeholder like "auto|cpu|cuda", file names elsewhere.
std::string bashCompletion(const std::vector<Command>& commands);

} // namespace sylva::cli
