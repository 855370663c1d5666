// A tolerant tokenizer for Quake III shader scripts: enough of the grammar to find each
// shader's first image stage (map / clampMap / animMap), ignoring everything else.
#include "shader_script.h"

#include <cctype>

namespace qvr {

namespace {

class Tokenizer {
public:
    explicit Tokenizer(std::string_view text) : m_text(text) {}

    // Next token, crossing lines; "" at the end. Braces are tokens of their own.
    std::string_view next() { return token(true); }
    // Next token on the current line only; "" at the end of the line.
    std::string_view nextOnLine() { return token(false); }

private:
    std::string_view token(bool cross_lines) {
        for (;;) {
            while (m_pos < m_text.size() &&
                   std::isspace(static_cast<unsigned char>(m_text[m_pos]))) {
                if (m_text[m_pos] == '\n' && !cross_lines)
                    return {};
                ++m_pos;
            }
            if (m_pos + 1 < m_text.size() && m_text[m_pos] == '/' && m_text[m_pos + 1] == '/') {
                while (m_pos < m_text.size() && m_text[m_pos] != '\n')
                    ++m_pos;
                continue;
            }
            if (m_pos + 1 < m_text.size() && m_text[m_pos] == '/' && m_text[m_pos + 1] == '*') {
                const size_t end = m_text.find("*/", m_pos + 2);
                m_pos = end == std::string_view::npos ? m_text.size() : end + 2;
                continue;
            }
            break;
        }
        if (m_pos >= m_text.size())
            return {};
        const size_t start = m_pos;
        if (m_text[m_pos] == '{' || m_text[m_pos] == '}')
            return m_text.substr(m_pos++, 1);
        if (m_text[m_pos] == '"') {
            const size_t end = m_text.find('"', m_pos + 1);
            const size_t stop = end == std::string_view::npos ? m_text.size() : end;
            m_pos = stop == m_text.size() ? stop : stop + 1;
            return m_text.substr(start + 1, stop - start - 1);
        }
        while (m_pos < m_text.size() && !std::isspace(static_cast<unsigned char>(m_text[m_pos])) &&
               m_text[m_pos] != '{' && m_text[m_pos] != '}')
            ++m_pos;
        return m_text.substr(start, m_pos - start);
    }

    std::string_view m_text;
    size_t m_pos = 0;
};

bool iequals(std::string_view a, std::string_view b) {
    if (a.size() != b.size())
        return false;
    for (size_t i = 0; i < a.size(); ++i) {
        if (std::tolower(static_cast<unsigned char>(a[i])) !=
            std::tolower(static_cast<unsigned char>(b[i])))
            return false;
    }
    return true;
}

bool isImagePath(std::string_view t) {
    return !t.empty() && t[0] != '$' && t[0] != '*';
}

}  // namespace

std::string stripImageExtension(std::string path) {
    if (path.size() > 4) {
        const std::string_view ext(path.data() + path.size() - 4, 4);
        if (iequals(ext, ".tga") || iequals(ext, ".jpg") || iequals(ext, ".png"))
            path.resize(path.size() - 4);
    }
    return path;
}

void ShaderLibrary::parse(std::string_view text) {
    Tokenizer tok(text);
    for (;;) {
        const std::string_view name = tok.next();
        if (name.empty())
            return;
        if (tok.next() != "{")
            return;  // malformed from here on
        std::string image;
        std::string editor_image;
        int depth = 1;
        while (depth > 0) {
            const std::string_view t = tok.next();
            if (t.empty())
                return;
            if (t == "{") {
                ++depth;
            } else if (t == "}") {
                --depth;
            } else if (depth == 2 && image.empty() &&
                       (iequals(t, "map") || iequals(t, "clampmap"))) {
                const std::string_view arg = tok.nextOnLine();
                if (isImagePath(arg))
                    image = arg;
            } else if (depth == 2 && image.empty() && iequals(t, "animmap")) {
                tok.nextOnLine();  // frequency
                const std::string_view arg = tok.nextOnLine();
                if (isImagePath(arg))
                    image = arg;
            } else if (depth == 1 && iequals(t, "qer_editorimage")) {
                const std::string_view arg = tok.nextOnLine();
                if (isImagePath(arg))
                    editor_image = arg;
            }
        }
        const std::string& chosen = image.empty() ? editor_image : image;
        const std::string key = normalizeGamePath(std::string(name));
        // The first definition wins, as in the game.
        if (!chosen.empty() && m_images.count(key) == 0)
            m_images[key] = stripImageExtension(normalizeGamePath(chosen));
    }
}

void ShaderLibrary::load(const GameFileSystem& files) {
    for (const auto& path : files.list("scripts/", ".shader")) {
        const auto bytes = files.read(path);
        if (!bytes)
            continue;
        parse(std::string_view(reinterpret_cast<const char*>(bytes->data()), bytes->size()));
    }
}

std::string ShaderLibrary::imageFor(const std::string& shader_name) const {
    const auto it = m_images.find(normalizeGamePath(shader_name));
    return it == m_images.end() ? std::string() : it->second;
}

}  // namespace qvr
