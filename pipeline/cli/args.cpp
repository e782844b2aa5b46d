// Parsing a subcommand's arguments against its option list, and its --help (args.h).
#include "pipeline/cli/args.h"

#include <cctype>
#include <cstdio>

#include "pipeline/cli/cli_util.h"

namespace sylva::cli {

void printHelp(const Command& c)
{
    std::printf("usage: sylva %s %s\n\n%s\n", c.name.c_str(), c.synopsis.c_str(), c.summary.c_str());
    if (!c.options.empty()) std::printf("\noptions:\n");
    for (const auto& o : c.options) {
        std::string left = o.name + (o.value.empty() ? "" : " " + o.value);
        std::printf("  %-24s %s\n", left.c_str(), o.help.c_str());
    }
    std::printf("  %-24s %s\n", "-h, --help", "this help");
}

Args::Args(const Command& cmd, const std::vector<std::string>& argv) : m_cmd(cmd)
{
    for (size_t a = 0; a < argv.size(); ++a) {
        std::string s = argv[a];
        if (s == "-h" || s == "--help") {
            m_help = true;
            continue;
        }
        if (s.size() > 1 && s[0] == '-' && !(s.size() > 1 && (std::isdigit((unsigned char)s[1]) || s[1] == '.'))) {
            std::string name = s, value;
            const size_t eq = s.find('=');
            const bool inlineValue = eq != std::string::npos;
            if (inlineValue) {
                name = s.substr(0, eq);
                value = s.substr(eq + 1);
            }
            if (name == "-o") name = "--output";
            const OptionSpec* spec = find(name);
            if (!spec) throw UsageError("unknown option " + name + " for 'sylva " + cmd.name + "' (see sylva " + cmd.name + " --help)");
            if (spec->value.empty()) {
                if (inlineValue) throw UsageError("option " + name + " takes no value");
                m_values.insert_or_assign(name, std::string("1"));
            } else {
                if (!inlineValue) {
                    if (a + 1 >= argv.size()) throw UsageError("option " + name + " needs a value (" + spec->value + ")");
                    value = argv[++a];
                }
                if (value.empty()) throw UsageError("option " + name + ": empty value");
                m_values[name] = value;
            }
        } else {
            m_positional.push_back(s);
        }
    }
    if (m_help) return;
    if (int(m_positional.size()) < cmd.minPositional) throw UsageError("'sylva " + cmd.name + "' needs " + cmd.synopsis);
    if (int(m_positional.size()) > cmd.maxPositional)
        throw UsageError("unexpected argument '" + m_positional[size_t(cmd.maxPositional)] + "' for 'sylva " + cmd.name + "'");
}

std::string Args::get(const std::string& name, const std::string& fallback) const
{
    auto it = m_values.find(name);
    return it == m_values.end() ? fallback : it->second;
}

std::string Args::require(const std::string& name) const
{
    if (!has(name)) throw UsageError("'sylva " + m_cmd.name + "' needs " + name + " (see sylva " + m_cmd.name + " --help)");
    return get(name);
}

const OptionSpec* Args::find(const std::string& name) const
{
    for (const auto& o : m_cmd.options)
        if (o.name == name) return &o;
    return nullptr;
}

} // namespace sylva::cli
