// pk3 archives through libzip and the game's layered, case-insensitive file lookup.
#include "qvr/scene/pk3.h"

#include <zip.h>

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <fstream>

#include <fmt/format.h>

namespace qvr {

namespace {

zip_t* asZip(void* p) {
    return static_cast<zip_t*>(p);
}

std::string zipErrorText(int code) {
    zip_error_t err;
    zip_error_init_with_code(&err, code);
    std::string text = zip_error_strerror(&err);
    zip_error_fini(&err);
    return text;
}

}  // namespace

std::string normalizeGamePath(std::string path) {
    std::replace(path.begin(), path.end(), '\\', '/');
    for (char& c : path)
        c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    // Strip leading "./" and "/" in any mix ("/./a", ".//a"), so a normalized path normalizes to
    // itself: the file system's keys are normalized once, its lookups normalize again.
    for (;;) {
        if (path.rfind("./", 0) == 0)
            path.erase(0, 2);
        else if (!path.empty() && path.front() == '/')
            path.erase(0, 1);
        else
            return path;
    }
}

Pk3Archive::~Pk3Archive() {
    if (m_zip != nullptr)
        zip_discard(asZip(m_zip));
}

Expected<std::unique_ptr<Pk3Archive>> Pk3Archive::open(const std::string& path) {
    std::unique_ptr<Pk3Archive> a(new Pk3Archive());
    a->m_label = path;
    int code = 0;
    a->m_zip = zip_open(path.c_str(), ZIP_RDONLY, &code);
    if (a->m_zip == nullptr)
        return makeError(
            fmt::format("{}: cannot open as a pk3 (zip) archive: {}", path, zipErrorText(code)));
    if (Status s = a->index(); !s)
        return makeError(s.error());
    return a;
}

Expected<std::unique_ptr<Pk3Archive>> Pk3Archive::fromBytes(std::vector<uint8_t> bytes,
                                                            std::string label) {
    std::unique_ptr<Pk3Archive> a(new Pk3Archive());
    a->m_label = std::move(label);
    a->m_bytes = std::move(bytes);
    zip_error_t err;
    zip_error_init(&err);
    // libzip wants a non-null buffer even for an empty input.
    static const uint8_t kEmpty = 0;
    const void* data = a->m_bytes.empty() ? &kEmpty : a->m_bytes.data();
    zip_source_t* src = zip_source_buffer_create(data, a->m_bytes.size(), 0, &err);
    if (src == nullptr) {
        std::string text = zip_error_strerror(&err);
        zip_error_fini(&err);
        return makeError(fmt::format("{}: {}", a->m_label, text));
    }
    a->m_zip = zip_open_from_source(src, ZIP_RDONLY, &err);
    if (a->m_zip == nullptr) {
        std::string text = zip_error_strerror(&err);
        zip_error_fini(&err);
        zip_source_free(src);
        return makeError(
            fmt::format("{}: cannot open as a pk3 (zip) archive: {}", a->m_label, text));
    }
    zip_error_fini(&err);
    if (Status s = a->index(); !s)
        return makeError(s.error());
    return a;
}

Status Pk3Archive::index() {
    const zip_int64_t n = zip_get_num_entries(asZip(m_zip), 0);
    if (n < 0)
        return makeError(fmt::format("{}: unreadable zip directory", m_label));
    for (zip_int64_t i = 0; i < n; ++i) {
        const char* name = zip_get_name(asZip(m_zip), static_cast<zip_uint64_t>(i), 0);
        if (name == nullptr)
            continue;
        std::string s = name;
        if (s.empty() || s.back() == '/')
            continue;
        m_names.push_back(std::move(s));
        m_zip_index.push_back(static_cast<uint64_t>(i));
    }
    return Status::success();
}

Expected<std::vector<uint8_t>> Pk3Archive::read(size_t i) const {
    if (i >= m_names.size())
        return makeError(fmt::format("{}: no member #{}", m_label, i));
    zip_t* z = asZip(m_zip);
    zip_stat_t st;
    zip_stat_init(&st);
    if (zip_stat_index(z, m_zip_index[i], 0, &st) != 0 || (st.valid & ZIP_STAT_SIZE) == 0)
        return makeError(fmt::format("{}: cannot stat {}", m_label, m_names[i]));
    if (st.size > kMaxArchiveMemberBytes)
        return makeError(fmt::format("{}: {} is {} bytes, more than the {} MB limit", m_label,
                                     m_names[i], st.size, kMaxArchiveMemberBytes >> 20));
    zip_file_t* f = zip_fopen_index(z, m_zip_index[i], 0);
    if (f == nullptr)
        return makeError(
            fmt::format("{}: cannot open {}: {}", m_label, m_names[i], zip_strerror(z)));
    // The size is what the archive claims: grow the buffer as bytes really arrive (doubling from
    // 64 KB) rather than allocating the claim up front, so a few hundred bytes of hostile zip
    // cannot make every read allocate and zero 256 MB before it turns out to be corrupt.
    const auto want = static_cast<size_t>(st.size);
    std::vector<uint8_t> out;
    size_t got = 0;
    while (got < want) {
        out.resize(std::min(want, std::max<size_t>(got * 2, size_t{64} << 10)));
        const zip_int64_t r = zip_fread(f, out.data() + got, out.size() - got);
        if (r <= 0)
            break;
        got += static_cast<size_t>(r);
    }
    out.resize(got);
    std::string err = got == want ? std::string() : zip_file_strerror(f);
    zip_fclose(f);
    if (got != want)
        return makeError(fmt::format("{}: {} is corrupt ({} of {} bytes read: {})", m_label,
                                     m_names[i], got, want, err));
    return out;
}

Expected<std::vector<uint8_t>> Pk3Archive::read(const std::string& name) const {
    const std::string key = normalizeGamePath(name);
    for (size_t i = 0; i < m_names.size(); ++i) {
        if (normalizeGamePath(m_names[i]) == key)
            return read(i);
    }
    return makeError(fmt::format("{}: no member {}", m_label, name));
}

Status GameFileSystem::addPk3Directory(const std::string& dir) {
    std::error_code ec;
    if (!std::filesystem::is_directory(dir, ec))
        return makeError(fmt::format("{}: no such directory", dir));
    std::vector<std::string> paths;
    for (const auto& e : std::filesystem::directory_iterator(dir, ec)) {
        std::string ext = e.path().extension().string();
        std::transform(ext.begin(), ext.end(), ext.begin(),
                       [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
        if (e.is_regular_file(ec) && ext == ".pk3")
            paths.push_back(e.path().string());
    }
    if (ec)
        return makeError(fmt::format("{}: {}", dir, ec.message()));
    std::sort(paths.begin(), paths.end());
    if (paths.empty())
        return makeError(fmt::format("{}: no .pk3 files", dir));
    for (const auto& p : paths) {
        if (Status s = addPk3(p); !s)
            return s;
    }
    return Status::success();
}

Status GameFileSystem::addPk3(const std::string& path) {
    auto a = Pk3Archive::open(path);
    if (!a)
        return makeError(a.error());
    addArchive(std::move(*a));
    return Status::success();
}

void GameFileSystem::addArchive(std::unique_ptr<Pk3Archive> archive) {
    const int id = static_cast<int>(m_archives.size());
    for (size_t i = 0; i < archive->names().size(); ++i)
        m_files[normalizeGamePath(archive->names()[i])] = Location{id, i, {}};
    m_archives.push_back(std::move(archive));
}

void GameFileSystem::addLooseDirectory(const std::string& dir) {
    namespace fs = std::filesystem;
    // Only the folders a level draws from, so pointing at a large directory stays cheap.
    for (const char* sub : {"textures", "scripts", "maps", "models"}) {
        std::error_code ec;
        const fs::path root = fs::path(dir) / sub;
        if (!fs::is_directory(root, ec))
            continue;
        for (auto it = fs::recursive_directory_iterator(root, ec);
             !ec && it != fs::recursive_directory_iterator(); it.increment(ec)) {
            if (!it->is_regular_file(ec))
                continue;
            const std::string rel = fs::relative(it->path(), dir, ec).generic_string();
            if (!ec)
                m_files[normalizeGamePath(rel)] = Location{-1, 0, it->path().string()};
        }
    }
}

bool GameFileSystem::exists(const std::string& game_path) const {
    return m_files.count(normalizeGamePath(game_path)) != 0;
}

std::optional<std::vector<uint8_t>> GameFileSystem::read(const std::string& game_path) const {
    const auto it = m_files.find(normalizeGamePath(game_path));
    if (it == m_files.end())
        return std::nullopt;
    const Location& loc = it->second;
    if (loc.archive >= 0) {
        auto bytes = m_archives[static_cast<size_t>(loc.archive)]->read(loc.member);
        if (!bytes)
            return std::nullopt;
        return std::move(*bytes);
    }
    std::ifstream in(loc.loose_path, std::ios::binary);
    if (!in)
        return std::nullopt;
    in.seekg(0, std::ios::end);
    const std::streamoff size = in.tellg();
    if (size < 0 || static_cast<uint64_t>(size) > kMaxArchiveMemberBytes)
        return std::nullopt;
    in.seekg(0);
    std::vector<uint8_t> out(static_cast<size_t>(size));
    in.read(reinterpret_cast<char*>(out.data()), size);
    if (!in)
        return std::nullopt;
    return out;
}

std::vector<std::string> GameFileSystem::list(const std::string& prefix,
                                              const std::string& suffix) const {
    const std::string p = normalizeGamePath(prefix);
    const std::string s = normalizeGamePath(suffix);
    std::vector<std::string> out;
    for (const auto& [key, loc] : m_files) {
        if (key.size() >= p.size() + s.size() && key.compare(0, p.size(), p) == 0 &&
            key.compare(key.size() - s.size(), s.size(), s) == 0)
            out.push_back(key);
    }
    std::sort(out.begin(), out.end());
    return out;
}

}  // namespace qvr
