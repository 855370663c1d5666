// Quake III's virtual file system: .pk3 archives (zip, read through libzip) and loose
// directories searched by lower-cased path, later sources overriding earlier ones as the game
// does, so a level's textures are found across every pk3 of an installation.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <unordered_map>
#include <vector>

#include "qvr/core/expected.h"

namespace qvr {

// Archive members larger than this are refused rather than allocated (largest OpenArena BSP is
// under 8 MB, the largest texture well under 4 MB).
inline constexpr uint64_t kMaxArchiveMemberBytes = 256ull << 20;

// One zip archive, opened from a file or from bytes in memory (tests, the fuzzer).
class Pk3Archive {
public:
    ~Pk3Archive();
    Pk3Archive(const Pk3Archive&) = delete;
    Pk3Archive& operator=(const Pk3Archive&) = delete;

    static Expected<std::unique_ptr<Pk3Archive>> open(const std::string& path);
    static Expected<std::unique_ptr<Pk3Archive>> fromBytes(std::vector<uint8_t> bytes,
                                                           std::string label);

    const std::string& label() const { return m_label; }
    // Member names as stored (directories excluded).
    const std::vector<std::string>& names() const { return m_names; }
    // Reads member i of names(); errors on a corrupt entry or one above kMaxArchiveMemberBytes.
    Expected<std::vector<uint8_t>> read(size_t i) const;
    Expected<std::vector<uint8_t>> read(const std::string& name) const;

private:
    Pk3Archive() = default;
    Status index();

    std::string m_label;
    std::vector<uint8_t> m_bytes;  // backing store when opened from memory
    void* m_zip = nullptr;         // zip_t*, kept opaque so libzip stays a private dependency
    std::vector<std::string> m_names;
    std::vector<uint64_t> m_zip_index;
};

// Lower-cased, '\\' → '/', no leading "./" or "/": the key Quake III looks files up by.
std::string normalizeGamePath(std::string path);

// An ordered set of archives and directories. Lookups are case-insensitive.
class GameFileSystem {
public:
    // Adds every *.pk3 of dir in name order (pak0 < pak1 < …, later wins). Missing dir: error.
    Status addPk3Directory(const std::string& dir);
    Status addPk3(const std::string& path);
    void addArchive(std::unique_ptr<Pk3Archive> archive);
    // Loose files under dir (e.g. an unpacked mod); searched after all earlier sources.
    void addLooseDirectory(const std::string& dir);

    bool exists(const std::string& game_path) const;
    std::optional<std::vector<uint8_t>> read(const std::string& game_path) const;
    // Every known path (normalized) that starts with prefix and ends with suffix, sorted.
    std::vector<std::string> list(const std::string& prefix, const std::string& suffix) const;
    size_t archiveCount() const { return m_archives.size(); }

private:
    struct Location {
        int archive = -1;  // −1: loose file
        size_t member = 0;
        std::string loose_path;
    };
    std::vector<std::unique_ptr<Pk3Archive>> m_archives;
    std::unordered_map<std::string, Location> m_files;
};

}  // namespace qvr
