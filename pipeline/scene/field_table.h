// A table of JSON fields, each declared once (key, type, default, bounds, a one-line doc), and the
// generic walks over it: read with key checks, write, summarize for people, document. Knows nothing of
// scenes; scene_fields.cpp declares the scene file's tables with it.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <optional>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "core/base/param_spec.h"
#include "pipeline/scene/json_codec.h"

namespace sylva::json {

// One documented field: a row of a reference table such as docs/SCENE.md's.
struct FieldDoc {
    std::string key;            // full path, arrays as [i]: "species[i].grow.seed"
    std::string type;           // the JSON type in words
    std::string defaultValue;   // JSON text of the default, or words ("required", "-"); empty for objects
    std::string rule;           // the values it takes, one line
    bool section = false;       // a top-level object or array (a section heading of the table)
};

// Bounds of a number; the message names them: "must lie in (0, 180) degrees", "must be >= 0 (metres; 0 = off)".
struct Bounds {
    double lo = -std::numeric_limits<double>::infinity();
    double hi = std::numeric_limits<double>::infinity();
    bool loOpen = false, hiOpen = false;
    const char* unit = "";              // after the interval: " degrees"
    const char* note = "";              // after the bound: " (metres; 0 = off)"
    const char* orZero = nullptr;       // also 0 is allowed, with this note: " (the species' default)"

    bool holds(double v) const
    {
        if (orZero && v == 0.0) return true;
        return (loOpen ? v > lo : v >= lo) && (hiOpen ? v < hi : v <= hi);
    }
    std::string problem() const
    {
        if (std::isinf(hi)) return std::string("must be ") + (loOpen ? "> " : ">= ") + fmt(lo) + note;
        return std::string(orZero ? std::string("must be 0") + orZero + " or lie in " : std::string("must lie in ")) +
               (loOpen ? "(" : "[") + fmt(lo) + ", " + fmt(hi) + (hiOpen ? ")" : "]") + unit + note;
    }
    bool any() const { return !std::isinf(lo) || !std::isinf(hi); }
};

// A row as the table declares it: the doc and the bounds its read checks (numbers, integers; none: unbounded).
struct FieldRow : FieldDoc {
    std::optional<Bounds> range;
};

// A closed range as docs/SCENE.md's rules write it: "1 .. 64".
inline std::string spanText(const ParamSpec& s) { return paramNumber(s.lo) + " .. " + paramNumber(s.hi); }

inline Bounds atLeast(double lo, const char* note = "") { return Bounds{.lo = lo, .note = note}; }
inline Bounds above(double lo) { return Bounds{.lo = lo, .loOpen = true}; }

template <class T>
struct Table;

// One field of an object of type T: how it is read, written, summarized and documented.
template <class T>
struct Field {
    using Read = std::function<void(JsonReader&, const QJsonValue&, const KeyPath&, T&)>;
    using Write = std::function<void(JsonWriter&, const T&, const KeyPath&, int indent)>;

    const char* key = "";
    const char* type = "";              // doc: the JSON type
    std::string rule;                   // doc: the values it takes
    const char* shownDefault = nullptr; // doc default where the default record cannot show it ("required", "-")
    const char* missing = nullptr;      // set: required, and this is the problem when it is absent
    bool readWhenAbsent = false;        // read also when absent (with an undefined value): optional objects
    bool nested = false;                // an object or array: documented by its own rows
    bool list = false;                  // an array of objects: documented as KEY[i]
    Read read;                          // null: read by the table's check (an alternative form)
    Write write;                        // null: not written
    std::function<bool(const T&)> writeIf;   // null: always written
    std::function<std::string(const T&)> summary;   // words for people; empty: nothing to say
    bool glue = false;                  // the summary joins the previous one without ", "
    std::function<void(std::vector<FieldRow>&, const std::string& path)> children;
    // A check across fields, run once this field is read (or found absent): object path, its JSON.
    std::function<void(JsonReader&, const QJsonObject&, const KeyPath&, T&)> then;
    std::optional<Bounds> range;        // the bounds the read checks (numbers, integers); the studio's widgets take theirs

    Field& doc(const char* t, std::string r)
    {
        type = t;
        rule = std::move(r);
        return *this;
    }
    Field& required(const char* problem)
    {
        missing = problem;
        return *this;
    }
    Field& shown(const char* text)
    {
        shownDefault = text;
        return *this;
    }
    Field& summarized(std::function<std::string(const T&)> f, bool joined = false)
    {
        summary = std::move(f);
        glue = joined;
        return *this;
    }
    Field& writtenIf(std::function<bool(const T&)> f)
    {
        writeIf = std::move(f);
        return *this;
    }
    Field& thenCheck(std::function<void(JsonReader&, const QJsonObject&, const KeyPath&, T&)> f)
    {
        then = std::move(f);
        return *this;
    }
    // The bounds of a field whose read checks them itself (custom reads).
    Field& ranged(Bounds b)
    {
        range = b;
        return *this;
    }
};

enum class Layout { Inline, Block };   // {"a": 1, "b": 2} on one line, or one field a line

// The fields of one JSON object, in the order they are read, written and listed.
template <class T>
struct Table {
    std::vector<Field<T>> fields;
    Layout layout = Layout::Inline;
    T defaults{};                       // the record the documented defaults are written from
    // Checks across fields, before and after the fields are read (object path, the object's JSON).
    std::function<void(JsonReader&, const QJsonObject&, const KeyPath&, T&)> before, after;

    std::vector<const char*> keys;      // the fields' keys, in order (for the unknown-key check)
};

// ---- the generic walks ----

template <class T>
void readObject(JsonReader& r, const QJsonObject& o, const KeyPath& path, T& out, const Table<T>& table)
{
    r.checkKeys(o, path, table.keys);
    if (table.before) table.before(r, o, path, out);
    for (const Field<T>& f : table.fields) {
        const QJsonValue v = o.value(QLatin1String(f.key));
        if (v.isUndefined() && f.missing) r.fail(path.field(f.key), f.missing);
        if (f.read && (!v.isUndefined() || f.readWhenAbsent)) f.read(r, v, path.field(f.key), out);
        if (f.then) f.then(r, o, path, out);
    }
    if (table.after) table.after(r, o, path, out);
}

inline void indentTo(JsonWriter& w, int indent) { w.text.append(size_t(indent), ' '); }

template <class T>
void writeObject(JsonWriter& w, const T& t, const KeyPath& path, const Table<T>& table, int indent)
{
    const bool block = table.layout == Layout::Block;
    w.raw("{");
    bool first = true;
    for (const Field<T>& f : table.fields) {
        if (!f.write || (f.writeIf && !f.writeIf(t))) continue;
        if (block) {
            w.raw(first ? "\n" : ",\n");
            indentTo(w, indent + 2);
        } else if (!first) {
            w.raw(", ");
        }
        first = false;
        w.key(f.key);
        f.write(w, t, path.field(f.key), indent + 2);
    }
    if (block) {
        w.raw("\n");
        indentTo(w, indent);
    }
    w.raw("}");
}

// The fields' summaries joined: "896x448, 1 spp, mode full".
template <class T>
std::string summarize(const T& t, const Table<T>& table)
{
    std::string s;
    for (const Field<T>& f : table.fields) {
        if (!f.summary) continue;
        const std::string part = f.summary(t);
        if (part.empty()) continue;
        if (!s.empty() && !f.glue) s += ", ";
        s += part;
    }
    return s;
}

// The rows documenting the table, each with its bounds; path: the object's own path ("species[i]"), empty at
// the top.
template <class T>
void documentFields(const Table<T>& table, const std::string& path, std::vector<FieldRow>& out)
{
    for (const Field<T>& f : table.fields) {
        FieldRow d;
        d.key = (path.empty() ? std::string(f.key) : path + "." + f.key) + (f.list ? "[i]" : "");
        d.type = f.type;
        d.rule = f.rule;
        d.section = path.empty() && f.nested;
        d.range = f.range;
        if (f.shownDefault) {
            d.defaultValue = f.shownDefault;
        } else if (!f.nested && f.write) {
            JsonWriter w;
            f.write(w, table.defaults, KeyPath{}, 0);
            d.defaultValue = std::move(w.text);
        }
        std::string childPath = d.key;
        out.push_back(std::move(d));
        if (f.children) f.children(out, childPath);
    }
}

// ---- building tables ----

// Adds fields to a table; each adder declares the key, how the value is read and written, and its
// bounds. Values are reached with Get: a member pointer or a callable T& -> V&.
template <class T>
class TableBuilder {
public:
    explicit TableBuilder(Layout layout, T defaults = T{})
    {
        table.layout = layout;
        table.defaults = std::move(defaults);
    }

    Table<T> table;

    Field<T>& custom(const char* key, typename Field<T>::Read read, typename Field<T>::Write write)
    {
        Field<T> f;
        f.key = key;
        f.read = std::move(read);
        f.write = std::move(write);
        table.fields.push_back(std::move(f));
        table.keys.push_back(key);
        return table.fields.back();
    }

    template <class Get>
    Field<T>& boolean(const char* key, Get get)
    {
        return custom(
            key, [get](JsonReader& r, const QJsonValue& v, const KeyPath& p, T& t) { ref(get, t) = r.boolean(v, p); },
            [get](JsonWriter& w, const T& t, const KeyPath&, int) { w.boolean(ref(get, t)); });
    }

    template <class Get>
    Field<T>& integer(const char* key, Get get, long long lo, long long hi)
    {
        Field<T>& f = custom(
            key,
            [get, lo, hi](JsonReader& r, const QJsonValue& v, const KeyPath& p, T& t) {
                using V = std::remove_cvref_t<decltype(ref(get, t))>;
                ref(get, t) = V(r.integer(v, p, lo, hi));
            },
            [get](JsonWriter& w, const T& t, const KeyPath&, int) {
                using V = std::remove_cvref_t<decltype(ref(get, t))>;
                if constexpr (std::is_same_v<V, uint64_t>) w.integer(uint64_t(ref(get, t)));
                else w.integer((long long)ref(get, t));
            });
        return f.ranged(Bounds{.lo = double(lo), .hi = double(hi)});
    }

    // A parameter declared by a ParamSpec (core/base/param_spec.h): key, bounds and doc line from it.
    template <class Get>
    Field<T>& param(const ParamSpec& s, Get get)
    {
        const std::string rule = s.bounded() ? std::string(s.help) + ", " + paramRange(s) : std::string(s.help);
        using V = std::remove_cvref_t<decltype(ref(get, std::declval<T&>()))>;
        if constexpr (std::is_integral_v<V>) {
            constexpr double most = double(std::numeric_limits<long long>::max());
            return integer(s.key, get, (long long)std::max(s.lo, -most), (long long)std::min(s.hi, most)).doc("integer", rule);
        } else {
            return number(s.key, get, Bounds{.lo = s.lo, .hi = s.hi, .loOpen = s.loOpen, .hiOpen = s.hiOpen}).doc("number", rule);
        }
    }

    // A float or double, checked against bounds.
    template <class Get>
    Field<T>& number(const char* key, Get get, Bounds bounds = {})
    {
        Field<T>& f = custom(
            key,
            [get, bounds](JsonReader& r, const QJsonValue& v, const KeyPath& p, T& t) {
                using V = std::remove_cvref_t<decltype(ref(get, t))>;
                V x;
                if constexpr (std::is_same_v<V, float>) x = r.floatNumber(v, p);
                else x = r.number(v, p);
                if (bounds.any() && !bounds.holds(double(x))) r.fail(p, bounds.problem() + ", got " + fmt(x));
                ref(get, t) = x;
            },
            [get](JsonWriter& w, const T& t, const KeyPath& p, int) { w.number(ref(get, t), p); });
        if (bounds.any()) f.range = bounds;
        return f;
    }

    // [x, y, z] of floats (glm::vec3) or doubles (glm::dvec3); nonZero: refuses a zero vector.
    template <class Get>
    Field<T>& vector(const char* key, Get get, bool nonZero = false)
    {
        return custom(
            key,
            [get, nonZero](JsonReader& r, const QJsonValue& v, const KeyPath& p, T& t) {
                using V = std::remove_cvref_t<decltype(ref(get, t))>;
                V x;
                if constexpr (std::is_same_v<V, glm::vec3>) x = r.vec3(v, p);
                else x = r.dvec3(v, p);
                if (nonZero && !(glm::length(x) >= 1e-12f)) r.fail(p, "must be a non-zero vector (length >= 1e-12)");
                ref(get, t) = x;
            },
            [get](JsonWriter& w, const T& t, const KeyPath& p, int) { w.vector3(ref(get, t), p); });
    }

    // [r, g, b], each in [lo, hi] (hi = float max: no upper bound).
    template <class Get>
    Field<T>& color(const char* key, Get get, float lo, float hi)
    {
        return custom(
            key, [get, lo, hi](JsonReader& r, const QJsonValue& v, const KeyPath& p, T& t) { ref(get, t) = r.color(v, p, lo, hi); },
            [get](JsonWriter& w, const T& t, const KeyPath& p, int) { w.vector3(ref(get, t), p); });
    }

    // A name from a fixed set: parse(name, &value) -> bool, name(value) -> const char*. The message
    // for an unknown name: "unknown WHAT 'x' (known: KNOWN)".
    template <class Get, class Parse, class Name>
    Field<T>& enumeration(const char* key, Get get, Parse parse, Name name, const char* what, const char* known)
    {
        return custom(
            key,
            [get, parse, what, known](JsonReader& r, const QJsonValue& v, const KeyPath& p, T& t) {
                const QString s = r.string(v, p);
                if (!parse(s.toStdString(), &ref(get, t)))
                    r.fail(p, std::string("unknown ") + what + " " + quoted(s) + " (known: " + known + ")");
            },
            [get, name](JsonWriter& w, const T& t, const KeyPath&, int) { w.string(name(ref(get, t))); });
    }

    // A nested object, optional: when absent it is read as {} (so its checks still run).
    template <class Get, class U>
    Field<T>& object(const char* key, Get get, const Table<U>& sub)
    {
        Field<T>& f = custom(
            key,
            [get, &sub](JsonReader& r, const QJsonValue& v, const KeyPath& p, T& t) {
                readObject(r, r.optionalObject(v, p), p, ref(get, t), sub);
            },
            [get, &sub](JsonWriter& w, const T& t, const KeyPath& p, int indent) { writeObject(w, ref(get, t), p, sub, indent); });
        f.readWhenAbsent = true;
        f.nested = true;
        f.children = [&sub](std::vector<FieldRow>& out, const std::string& path) { documentFields(sub, path, out); };
        return f;
    }

    // A nested object held in a std::optional: set when present, written when set.
    template <class Get, class U>
    Field<T>& optionalObject(const char* key, Get get, const Table<U>& sub)
    {
        Field<T>& f = custom(
            key,
            [get, &sub](JsonReader& r, const QJsonValue& v, const KeyPath& p, T& t) {
                const QJsonObject o = r.object(v, p);
                ref(get, t).emplace();
                readObject(r, o, p, *ref(get, t), sub);
            },
            [get, &sub](JsonWriter& w, const T& t, const KeyPath& p, int indent) { writeObject(w, *ref(get, t), p, sub, indent); });
        f.writeIf = [get](const T& t) { return ref(get, t).has_value(); };
        f.nested = true;
        f.children = [&sub](std::vector<FieldRow>& out, const std::string& path) { documentFields(sub, path, out); };
        return f;
    }

    // A required array of objects, one a line when written; at least one (else the problem `empty`; null:
    // an empty array is allowed),
    // at most max (else the problem `tooMany`).
    template <class Get, class U>
    Field<T>& array(const char* key, Get get, const Table<U>& sub, const char* empty, size_t max = std::numeric_limits<size_t>::max(),
                    const char* tooMany = "too many")
    {
        Field<T>& f = custom(
            key,
            [get, &sub, empty, max, tooMany](JsonReader& r, const QJsonValue& v, const KeyPath& p, T& t) {
                const QJsonArray list = r.array(v, p);
                if (list.isEmpty() && empty) r.fail(p, empty);
                if (size_t(list.size()) > max) r.fail(p, tooMany);
                auto& items = ref(get, t);
                items.resize(size_t(list.size()));
                for (qsizetype i = 0; i < list.size(); ++i) {
                    const KeyPath ip = p.at(i);
                    readObject(r, r.object(list.at(i), ip), ip, items[size_t(i)], sub);
                }
            },
            [get, &sub](JsonWriter& w, const T& t, const KeyPath& p, int indent) {
                const auto& items = ref(get, t);
                w.raw("[");
                for (size_t i = 0; i < items.size(); ++i) {
                    w.raw(i ? ",\n" : "\n");
                    indentTo(w, indent + 2);
                    writeObject(w, items[i], p.at(qsizetype(i)), sub, indent + 2);
                }
                w.raw("\n");
                indentTo(w, indent);
                w.raw("]");
            });
        f.nested = true;
        f.list = true;
        f.required("missing (required)");
        f.children = [&sub](std::vector<FieldRow>& out, const std::string& path) { documentFields(sub, path, out); };
        return f;
    }

private:
    template <class Get, class R>
    static decltype(auto) ref(const Get& get, R& t)
    {
        if constexpr (std::is_member_object_pointer_v<Get>) return (t.*get);
        else return get(t);
    }
};

} // namespace sylva::json
