// libFuzzer target for pk3 archives (scene/pk3.h): any bytes either open as a zip whose every
// member reads within kMaxArchiveMemberBytes or fails with a message, and an opened archive
// answers the game file system's lookups (normalized names, listing, reads) without crashing.
// bsp_fuzz parses the levels inside an archive; this one covers the archive layer itself.
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "qvr/core/check.h"
#include "qvr/scene/pk3.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    auto archive = qvr::Pk3Archive::fromBytes(std::vector<uint8_t>(data, data + size), "fuzz.pk3");
    if (!archive.ok()) {
        QVR_CHECK(!archive.error().empty());
        return 0;
    }
    const std::vector<std::string> names = (*archive)->names();
    for (size_t i = 0; i < names.size() && i < 16; ++i) {
        auto member = (*archive)->read(i);
        if (member.ok()) {
            QVR_CHECK(member->size() <= qvr::kMaxArchiveMemberBytes);
            auto by_name = (*archive)->read(names[i]);
            QVR_CHECK(by_name.ok() || !by_name.error().empty());
        } else {
            QVR_CHECK(!member.error().empty());
        }
    }
    QVR_CHECK(!(*archive)->read(names.size()).ok());  // past the end: an error, not a crash
    qvr::GameFileSystem files;
    files.addArchive(std::move(*archive));
    const std::vector<std::string> listed = files.list("", "");
    for (size_t i = 0; i < listed.size() && i < 16; ++i) {
        QVR_CHECK(files.exists(listed[i]));
        QVR_CHECK(listed[i] == qvr::normalizeGamePath(listed[i]));
        (void)files.read(listed[i]);
    }
    for (size_t i = 0; i < names.size() && i < 16; ++i)
        (void)files.read(names[i]);
    return 0;
}
