// Parsing JSON text with key-path messages: QJsonDocument does the parse, a token scanner names where.
#include "pipeline/scene/json_codec.h"

#include <algorithm>
#include <cctype>
#include <string_view>
#include <unordered_set>
#include <vector>

#include <QByteArray>
#include <QJsonDocument>
#include <QJsonParseError>

#include "core/base/error.h"

namespace sylva::json {

namespace {

// Walks JSON text token by token, keeping the key path; QJsonDocument does the real parse. Names the
// key path at a syntax error's offset, and finds repeated keys (QJsonObject silently keeps the last).
class JsonScanner {
public:
    explicit JsonScanner(std::string_view text) : m_text(text) {}

    // Scans [0, end). With findDuplicates, stops at the first repeated key of an object and returns
    // false; path() then names that key.
    bool scan(size_t end, bool findDuplicates)
    {
        end = std::min(end, m_text.size());
        size_t i = 0;
        while (i < end) {
            const char c = m_text[i];
            if (c == '{' || c == '[') {
                push(c == '{');
                ++i;
            } else if (c == '}' || c == ']') {
                if (m_depth > 0) --m_depth;
                ++i;
            } else if (c == ',') {
                if (m_depth > 0) {
                    Frame& f = m_stack[m_depth - 1];
                    if (f.object) {
                        f.expectKey = true;
                        f.key = {};
                    } else {
                        ++f.index;
                    }
                }
                ++i;
            } else if (c == '"') {
                size_t j = i + 1;
                while (j < m_text.size() && m_text[j] != '"') j += m_text[j] == '\\' ? 2 : 1;
                j = std::min(j, m_text.size());
                if (m_depth > 0 && m_stack[m_depth - 1].object && m_stack[m_depth - 1].expectKey) {
                    Frame& f = m_stack[m_depth - 1];
                    f.key = m_text.substr(i + 1, j - i - 1);
                    f.expectKey = false;
                    if (findDuplicates && j < end && !f.addKey(f.key)) return false;
                }
                i = j + 1;
            } else {
                ++i;
            }
        }
        return true;
    }

    std::string path() const
    {
        std::string s;
        for (size_t d = 0; d < m_depth; ++d) {
            const Frame& f = m_stack[d];
            if (f.object) {
                if (f.expectKey) break;
                if (!s.empty()) s += '.';
                s += f.key;
            } else {
                s += '[' + std::to_string(f.index) + ']';
            }
        }
        return s;
    }

private:
    struct Frame {
        bool object = false;
        bool expectKey = false;
        size_t index = 0;
        std::string_view key;
        std::vector<std::string_view> keys;        // the keys seen, while few
        std::unordered_set<std::string_view> many;  // the keys seen, once many (no quadratic checks)

        bool addKey(std::string_view k)
        {
            if (many.empty() && keys.size() < 16) {
                if (std::find(keys.begin(), keys.end(), k) != keys.end()) return false;
                keys.push_back(k);
                return true;
            }
            if (many.empty()) many.insert(keys.begin(), keys.end());
            return many.insert(k).second;
        }
    };

    void push(bool object)
    {
        if (m_depth == m_stack.size()) m_stack.emplace_back();
        Frame& f = m_stack[m_depth++];
        f.object = object;
        f.expectKey = object;
        f.index = 0;
        f.key = {};
        f.keys.clear();
        f.many.clear();
    }

    std::string_view m_text;
    std::vector<Frame> m_stack;   // frames are reused, so a million small objects allocate nothing
    size_t m_depth = 0;
};

std::string lineColumn(std::string_view text, size_t offset)
{
    offset = std::min(offset, text.size());
    size_t line = 1, lineStart = 0;
    for (size_t i = 0; i < offset; ++i)
        if (text[i] == '\n') {
            ++line;
            lineStart = i + 1;
        }
    return "line " + std::to_string(line) + ", column " + std::to_string(offset - lineStart + 1);
}

} // namespace

QJsonObject parseObject(std::string_view text, const std::string& name, const char* notAnObject)
{
    QJsonParseError parseError;
    const QJsonDocument doc =
        QJsonDocument::fromJson(QByteArray::fromRawData(text.data(), qsizetype(text.size())), &parseError);
    if (doc.isNull()) {
        size_t offset = size_t(std::max(0, parseError.offset));
        JsonScanner scanner(text);
        if (parseError.error == QJsonParseError::IllegalNumber) {
            // Qt points after the number; name the number and where it starts.
            auto numberChar = [](char c) { return std::isalnum((unsigned char)c) || c == '+' || c == '-' || c == '.'; };
            offset = std::min(offset, text.size());
            size_t start = offset;
            while (start > 0 && numberChar(text[start - 1])) --start;
            size_t stop = start;
            while (stop < text.size() && numberChar(text[stop]) && stop - start < 40) ++stop;
            scanner.scan(start, false);
            const std::string path = scanner.path();
            throw Error(name + ": " + (path.empty() ? "" : path + ": ") + "'" + std::string(text.substr(start, stop - start)) +
                        "' is not a finite number within double range (" + lineColumn(text, start) + ")");
        }
        // Qt's offset is just past the offending character.
        offset = std::min(offset > 0 ? offset - 1 : 0, text.size());
        scanner.scan(offset, false);
        const std::string path = scanner.path();
        throw Error(name + ": " + (path.empty() ? "" : path + ": ") + "malformed JSON at " + lineColumn(text, offset) + ": " +
                    parseError.errorString().toStdString());
    }
    if (!doc.isObject()) throw Error(name + ": " + notAnObject);
    JsonScanner scanner(text);
    if (!scanner.scan(text.size(), true))
        throw Error(name + ": " + scanner.path() + ": duplicate key (each key may appear once per object)");
    return doc.object();
}

} // namespace sylva::json
