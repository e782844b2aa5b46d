// Strict typed reading and exact writing of JSON values, with key paths in every message. Knows nothing
// of scenes: the scene-file field table (scene_fields.h) is built on it.
#pragma once

#include <cstdint>
#include <initializer_list>
#include <string>
#include <string_view>
#include <vector>

#include <QJsonArray>
#include <QJsonObject>
#include <QJsonValue>
#include <QString>
#include <glm/glm.hpp>

namespace sylva::json {

// A JSON key path built on the stack while walking ("instances[3].scale"); text only for messages.
struct KeyPath {
    const KeyPath* parent = nullptr;
    const char* key = nullptr;   // member name; nullptr for an array element (or the root)
    qsizetype index = -1;        // array element index

    KeyPath field(const char* k) const { return KeyPath{this, k, -1}; }
    KeyPath at(qsizetype i) const { return KeyPath{this, nullptr, i}; }
    std::string text() const;
};

std::string joinPath(const std::string& path, const std::string& key);

// Shortest text that reads back as the same value (0.1f prints as 0.1, not 0.100000001).
std::string fmt(double v);
std::string fmt(float v);
template <class V>
std::string fmt3(const V& v)
{
    std::string s(1, '(');   // appended: GCC 12 warns falsely (-Wrestrict) on "(" + temporary
    s += fmt(v.x);
    s += ", ";
    s += fmt(v.y);
    s += ", ";
    s += fmt(v.z);
    s += ')';
    return s;
}
std::string quoted(const QString& s);   // 's'
std::string nameList(const std::vector<std::string>& names);   // "a, b, c"

// Typed reads of parsed JSON values. Every failure throws Error "NAME: KEY.PATH: problem".
class JsonReader {
public:
    explicit JsonReader(std::string name) : m_name(std::move(name)) {}
    const std::string& name() const { return m_name; }

    [[noreturn]] void failText(const std::string& path, const std::string& problem) const;
    [[noreturn]] void fail(const KeyPath& path, const std::string& problem) const { failText(path.text(), problem); }
    [[noreturn]] void wrongType(const QJsonValue& v, const KeyPath& path, const char* expected) const;

    // Unknown keys are errors naming the key and the known ones (in the order given).
    void checkKeys(const QJsonObject& o, const KeyPath& path, const std::vector<const char*>& known) const;

    QJsonObject object(const QJsonValue& v, const KeyPath& path) const;
    QJsonObject optionalObject(const QJsonValue& v, const KeyPath& path) const;   // empty when absent
    QJsonArray array(const QJsonValue& v, const KeyPath& path) const;
    double number(const QJsonValue& v, const KeyPath& path) const;                 // finite
    float toFloat(double d, const KeyPath& path) const;                            // within float range
    float floatNumber(const QJsonValue& v, const KeyPath& path) const { return toFloat(number(v, path), path); }
    long long integer(const QJsonValue& v, const KeyPath& path, long long lo, long long hi) const;
    bool boolean(const QJsonValue& v, const KeyPath& path) const;
    QString string(const QJsonValue& v, const KeyPath& path) const;
    QJsonArray triple(const QJsonValue& v, const KeyPath& path) const;             // an array of three
    glm::dvec3 dvec3(const QJsonValue& v, const KeyPath& path) const;
    glm::vec3 vec3(const QJsonValue& v, const KeyPath& path) const;
    glm::vec3 color(const QJsonValue& v, const KeyPath& path, float lo, float hi) const;   // each in [lo, hi]
    glm::vec3 perChannel(const QJsonValue& v, const KeyPath& path) const;          // a number or [r, g, b]

private:
    std::string m_name;
};

// Appends JSON text; numbers in the shortest form that reads back exactly, checked finite.
class JsonWriter {
public:
    std::string text;
    std::string name = "json";   // names the document in messages

    void raw(std::string_view s) { text += s; }
    void key(const char* k);
    void string(std::string_view s);
    void boolean(bool b) { text += b ? "true" : "false"; }
    void integer(long long n) { text += std::to_string(n); }
    void integer(uint64_t n) { text += std::to_string(n); }
    void number(double v, const KeyPath& path);
    void number(float v, const KeyPath& path);
    template <class V>
    void vector3(const V& v, const KeyPath& path)
    {
        text += '[';
        for (int i = 0; i < 3; ++i) {
            if (i) text += ", ";
            number(v[i], path.at(i));
        }
        text += ']';
    }
};

// Parses JSON text that must hold an object. Throws Error "NAME: KEY.PATH: ..." for malformed JSON
// (line, column and the key path where the parser stopped), a number outside double range, a
// repeated key in one object, or a document that is not an object.
QJsonObject parseObject(std::string_view text, const std::string& name, const char* notAnObject);

} // namespace sylva::json
