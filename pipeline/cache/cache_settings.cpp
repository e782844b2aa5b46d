// The grid cache's size limit in the user's settings, and sizes and durations as text (grid_cache.h).
#include <cctype>
#include <cmath>
#include <cstdio>
#include <string>

#include <QSettings>

#include "core/base/error.h"
#include "pipeline/cache/grid_cache.h"

namespace sylva {

uint64_t cacheSizeLimitSetting()
{
    const QSettings settings(QSettings::NativeFormat, QSettings::UserScope, QStringLiteral("Sylva"), QStringLiteral("sylva"));
    const QVariant value = settings.value(QStringLiteral("cache/maxSize"));
    if (!value.isValid()) return kDefaultCacheLimit;
    const std::string text = value.toString().trimmed().toLower().toStdString();
    if (text == "none" || text == "off" || text == "unlimited") return 0;
    const auto bytes = parseByteSize(text);
    return bytes ? *bytes : kDefaultCacheLimit;
}

void setCacheSizeLimitSetting(uint64_t bytes)
{
    QSettings settings(QSettings::NativeFormat, QSettings::UserScope, QStringLiteral("Sylva"), QStringLiteral("sylva"));
    settings.setValue(QStringLiteral("cache/maxSize"), bytes == 0 ? QStringLiteral("none") : QString::number(qulonglong(bytes)));
    settings.sync();
    if (settings.status() != QSettings::NoError) throw Error(settings.fileName().toStdString() + ": cannot write the settings");
}

std::string cacheSettingsPath()
{
    const QSettings settings(QSettings::NativeFormat, QSettings::UserScope, QStringLiteral("Sylva"), QStringLiteral("sylva"));
    return settings.fileName().toStdString();
}

namespace {

// The non-negative number a size or duration starts with ("1.5G", "30d"): its value and the unit text
// after it; false when the text does not start with one (signs refused).
bool leadingNumber(const std::string& t, double* value, std::string* unit)
{
    size_t used = 0;
    try {
        *value = std::stod(t, &used);
    } catch (...) {
        return false;
    }
    if (used == 0 || !std::isfinite(*value) || *value < 0.0 || t[0] == '-' || t[0] == '+') return false;
    *unit = t.substr(used);
    return true;
}

} // namespace

std::optional<uint64_t> parseByteSize(std::string_view text)
{
    std::string t(text);
    while (!t.empty() && std::isspace((unsigned char)t.back())) t.pop_back();
    double value = 0.0;
    std::string unit;
    if (!leadingNumber(t, &value, &unit)) return std::nullopt;
    while (!unit.empty() && unit.front() == ' ') unit.erase(unit.begin());
    for (char& c : unit) c = char(std::tolower((unsigned char)c));
    if (unit.size() >= 2 && unit.substr(unit.size() - 2) == "ib") unit.resize(unit.size() - 2);
    else if (unit.size() >= 2 && unit.back() == 'b') unit.pop_back();
    else if (unit == "b" || unit == "bytes") unit.clear();
    int shift = 0;
    if (unit.empty()) shift = 0;
    else if (unit == "k") shift = 10;
    else if (unit == "m") shift = 20;
    else if (unit == "g") shift = 30;
    else if (unit == "t") shift = 40;
    else return std::nullopt;
    const double bytes = std::ldexp(value, shift);
    if (bytes >= 18446744073709551616.0) return std::nullopt;
    return uint64_t(std::llround(bytes));
}

std::optional<int64_t> parseDuration(std::string_view text)
{
    const std::string t(text);
    double value = 0.0;
    std::string unit;
    if (!leadingNumber(t, &value, &unit)) return std::nullopt;
    double scale = 0.0;
    if (unit.empty() || unit == "d") scale = 86400.0;
    else if (unit == "s") scale = 1.0;
    else if (unit == "m" || unit == "min") scale = 60.0;
    else if (unit == "h") scale = 3600.0;
    else if (unit == "w") scale = 7 * 86400.0;
    else return std::nullopt;
    if (value * scale > 1e15) return std::nullopt;
    return int64_t(std::llround(value * scale));
}

std::string formatBytes(uint64_t bytes)
{
    if (bytes < 1024) return std::to_string(bytes) + (bytes == 1 ? " byte" : " bytes");
    static const char* units[] = {"KiB", "MiB", "GiB", "TiB", "PiB"};
    double v = double(bytes) / 1024.0;
    int u = 0;
    while (v >= 1024.0 && u < 4) {
        v /= 1024.0;
        ++u;
    }
    char text[32];
    std::snprintf(text, sizeof text, "%.2f %s", v, units[u]);
    return text;
}

} // namespace sylva
