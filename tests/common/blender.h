// Blender for the tests labelled `blender`: where the program is (SYLVA_BLENDER, else `blender` on the PATH;
// empty when there is none, and the tests skip with a message) and a background run of a Python file.
#pragma once

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <QtGlobal>

namespace sylva::test {

inline std::string blenderProgram()
{
    if (const char* e = std::getenv("SYLVA_BLENDER")) return e;
    const char* path = std::getenv("PATH");
    std::string p = path ? path : "";
    size_t start = 0;
    while (start <= p.size()) {
        const size_t end = p.find(':', start);
        const std::string d = p.substr(start, end == std::string::npos ? std::string::npos : end - start);
        if (!d.empty() && std::filesystem::exists(d + "/blender")) return d + "/blender";
        if (end == std::string::npos) break;
        start = end + 1;
    }
    return {};
}

// Runs blender -b with a Python file (its arguments after "--"); returns its output.
inline std::string runBlender(const std::string& blender, const std::string& script, const std::string& args = {})
{
    const std::string log = script + ".log";
    const std::string cmd = "nice -n 5 '" + blender + "' -b --factory-startup --python '" + script + "' -- " + args + " > '" + log + "' 2>&1";
    const int rc = std::system(cmd.c_str());
    std::ifstream in(log);
    std::stringstream ss;
    ss << in.rdbuf();
    const std::string out = ss.str();
    if (rc != 0) qWarning("%s", out.c_str());
    return out;
}

// The rest of the line after the first `key` in `text` (a script's "KEY=value" print).
inline std::string valueAfter(const std::string& text, const std::string& key)
{
    const size_t at = text.find(key);
    if (at == std::string::npos) return {};
    const size_t end = text.find('\n', at);
    return text.substr(at + key.size(), end - at - key.size());
}

} // namespace sylva::test
