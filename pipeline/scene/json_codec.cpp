// Typed JSON reads with key-path messages and an exact number writer (json_codec.h).
#include "pipeline/scene/json_codec.h"

#include <charconv>
#include <cmath>
#include <cstdio>
#include <limits>

#include "core/base/error.h"

namespace sylva::json {

std::string KeyPath::text() const
{
    std::string s = parent ? parent->text() : std::string();
    if (key) {
        if (!s.empty()) s += '.';
        s += key;
    } else if (index >= 0) {
        s += '[' + std::to_string(index) + ']';
    }
    return s;
}

std::string joinPath(const std::string& path, const std::string& key) { return path.empty() ? key : path + "." + key; }

namespace {

template <class T>
std::string shortest(T v)
{
    char buf[64];
    const auto r = std::to_chars(buf, buf + sizeof buf, v);
    return std::string(buf, r.ptr);
}

const char* typeName(const QJsonValue& v)
{
    switch (v.type()) {
    case QJsonValue::Null: return "null";
    case QJsonValue::Bool: return "true/false";
    case QJsonValue::Double: return "a number";
    case QJsonValue::String: return "a string";
    case QJsonValue::Array: return "an array";
    case QJsonValue::Object: return "an object";
    case QJsonValue::Undefined: return "nothing";
    }
    return "something else";
}

} // namespace

std::string fmt(double v) { return shortest(v); }
std::string fmt(float v) { return shortest(v); }

std::string quoted(const QString& s)
{
    std::string q(1, '\'');   // appended, not "'" + ...: GCC 12 warns falsely (-Wrestrict) on literal + temporary
    q += s.toStdString();
    q += '\'';
    return q;
}

std::string nameList(const std::vector<std::string>& names)
{
    std::string s;
    for (const auto& n : names) s += (s.empty() ? "" : ", ") + n;
    return s;
}

// ---- reading ----

void JsonReader::failText(const std::string& path, const std::string& problem) const
{
    throw Error(m_name + ": " + (path.empty() ? "" : path + ": ") + problem);
}

void JsonReader::wrongType(const QJsonValue& v, const KeyPath& path, const char* expected) const
{
    fail(path, std::string("expected ") + expected + ", got " + typeName(v));
}

void JsonReader::checkKeys(const QJsonObject& o, const KeyPath& path, const std::vector<const char*>& known) const
{
    qsizetype found = 0;
    for (const char* k : known) found += o.contains(QLatin1String(k));
    if (found == o.size()) return;
    for (auto it = o.begin(); it != o.end(); ++it) {
        const QString key = it.key();
        bool ok = false;
        for (const char* k : known) ok = ok || key == QLatin1String(k);
        if (!ok) {
            std::string list;
            for (const char* k : known) list += (list.empty() ? "" : ", ") + std::string(k);
            failText(joinPath(path.text(), key.toStdString()), "unknown field (known here: " + list + ")");
        }
    }
}

QJsonObject JsonReader::object(const QJsonValue& v, const KeyPath& path) const
{
    if (!v.isObject()) wrongType(v, path, "an object");
    return v.toObject();
}

QJsonObject JsonReader::optionalObject(const QJsonValue& v, const KeyPath& path) const
{
    return v.isUndefined() ? QJsonObject() : object(v, path);
}

QJsonArray JsonReader::array(const QJsonValue& v, const KeyPath& path) const
{
    if (!v.isArray()) wrongType(v, path, "an array");
    return v.toArray();
}

double JsonReader::number(const QJsonValue& v, const KeyPath& path) const
{
    if (!v.isDouble()) wrongType(v, path, "a number");
    const double d = v.toDouble();
    if (!std::isfinite(d)) fail(path, "must be a finite number");
    return d;
}

float JsonReader::toFloat(double d, const KeyPath& path) const
{
    if (std::fabs(d) > double(std::numeric_limits<float>::max())) fail(path, fmt(d) + " is out of range");
    return float(d);
}

long long JsonReader::integer(const QJsonValue& v, const KeyPath& path, long long lo, long long hi) const
{
    const double d = number(v, path);
    if (d != std::floor(d)) fail(path, "must be a whole number, got " + fmt(d));
    std::string range(1, '[');
    range += std::to_string(lo) + ", " + std::to_string(hi) + "]";
    if (d < double(lo) || d > double(hi)) fail(path, "must lie in " + range + ", got " + fmt(d));
    const long long n = v.toInteger(lo - 1);
    if (n < lo || n > hi) fail(path, "must lie in " + range + ", got " + fmt(d));
    return n;
}

bool JsonReader::boolean(const QJsonValue& v, const KeyPath& path) const
{
    if (!v.isBool()) wrongType(v, path, "true or false");
    return v.toBool();
}

QString JsonReader::string(const QJsonValue& v, const KeyPath& path) const
{
    if (!v.isString()) wrongType(v, path, "a string");
    return v.toString();
}

QJsonArray JsonReader::triple(const QJsonValue& v, const KeyPath& path) const
{
    if (!v.isArray()) wrongType(v, path, "an array of three numbers");
    const QJsonArray a = v.toArray();
    if (a.size() != 3) fail(path, "expected three numbers, got " + std::to_string(a.size()));
    return a;
}

glm::dvec3 JsonReader::dvec3(const QJsonValue& v, const KeyPath& path) const
{
    const QJsonArray a = triple(v, path);
    return {number(a.at(0), path.at(0)), number(a.at(1), path.at(1)), number(a.at(2), path.at(2))};
}

glm::vec3 JsonReader::vec3(const QJsonValue& v, const KeyPath& path) const
{
    const QJsonArray a = triple(v, path);
    return {floatNumber(a.at(0), path.at(0)), floatNumber(a.at(1), path.at(1)), floatNumber(a.at(2), path.at(2))};
}

glm::vec3 JsonReader::color(const QJsonValue& v, const KeyPath& path, float lo, float hi) const
{
    const QJsonArray a = triple(v, path);
    glm::vec3 c;
    for (int i = 0; i < 3; ++i) {
        c[i] = floatNumber(a.at(i), path.at(i));
        if (!(c[i] >= lo && c[i] <= hi))
            fail(path.at(i), "must lie in [" + fmt(lo) + ", " + (hi == std::numeric_limits<float>::max() ? "inf" : fmt(hi)) +
                                 "], got " + fmt(c[i]));
    }
    return c;
}

glm::vec3 JsonReader::perChannel(const QJsonValue& v, const KeyPath& path) const
{
    if (v.isDouble()) return glm::vec3(floatNumber(v, path));
    if (!v.isArray()) wrongType(v, path, "a number or [r, g, b]");
    return vec3(v, path);
}

// ---- writing ----

void JsonWriter::key(const char* k)
{
    text += '"';
    text += k;
    text += "\": ";
}

void JsonWriter::string(std::string_view s)
{
    text += '"';
    for (const char c : s) {
        switch (c) {
        case '"': text += "\\\""; break;
        case '\\': text += "\\\\"; break;
        case '\n': text += "\\n"; break;
        case '\r': text += "\\r"; break;
        case '\t': text += "\\t"; break;
        default:
            if ((unsigned char)c < 0x20) {
                char buf[8];
                std::snprintf(buf, sizeof buf, "\\u%04x", unsigned((unsigned char)c));
                text += buf;
            } else {
                text += c;
            }
        }
    }
    text += '"';
}

void JsonWriter::number(double v, const KeyPath& path)
{
    if (!std::isfinite(v)) throw Error(name + ": " + path.text() + ": cannot write the non-finite number " + fmt(v));
    if (v == 0.0) v = 0.0;   // -0 reads back as 0: write 0, so rewriting a read scene gives the same text
    char buf[64];
    const auto r = std::to_chars(buf, buf + sizeof buf, v);
    text.append(buf, r.ptr);
}

void JsonWriter::number(float v, const KeyPath& path)
{
    if (!std::isfinite(v)) throw Error(name + ": " + path.text() + ": cannot write the non-finite number " + fmt(v));
    if (v == 0.0f) v = 0.0f;
    char buf[64];
    auto r = std::to_chars(buf, buf + sizeof buf, v);
    // The shortest float text is read as a double, then rounded to float: keep it only when that
    // gives v back (double rounding could differ in rare cases), else write the double exactly.
    double back = 0.0;
    std::from_chars(buf, r.ptr, back);
    if (float(back) != v) r = std::to_chars(buf, buf + sizeof buf, double(v));
    text.append(buf, r.ptr);
}

} // namespace sylva::json
