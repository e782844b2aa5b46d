// A subcommand's description (name, synopsis, options, what runs it) and its parsed arguments.
#pragma once

#include <map>
#include <string>
#include <vector>

namespace sylva::cli {

// One option of a subcommand: --name VALUE, or a flag when value is empty.
struct OptionSpec {
    std::string name;
    std::string value;   // placeholder shown in help; empty for flags
    std::string help;
};

class Args;

// One `sylva` command: what its --help shows, how many positional arguments it takes, and its function
// (cmd_NAME.cpp), which returns the exit code and throws UsageError (2) or any other exception (1).
struct Command {
    std::string name;
    std::string synopsis;
    std::string summary;
    std::vector<OptionSpec> options;
    int minPositional = 0, maxPositional = 0;
    int (*run)(const Args&) = nullptr;
};

// Prints `sylva NAME --help`.
void printHelp(const Command& command);

// Parsed arguments of one subcommand. Throws UsageError for an unknown option, a missing or empty value
// and a wrong number of positional arguments (not when --help is given).
class Args {
public:
    Args(const Command& cmd, const std::vector<std::string>& argv);
    bool help() const { return m_help; }
    bool has(const std::string& name) const { return m_values.count(name) != 0; }
    std::string get(const std::string& name, const std::string& fallback = {}) const;
    // The value of a required option; UsageError naming it when absent.
    std::string require(const std::string& name) const;
    const std::vector<std::string>& positional() const { return m_positional; }

private:
    const OptionSpec* find(const std::string& name) const;
    const Command& m_cmd;
    std::map<std::string, std::string> m_values;
    std::vector<std::string> m_positional;
    bool m_help = false;
};

} // namespace sylva::cli
