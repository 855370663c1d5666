// Seeds for bsp_fuzz: the tests' generated level as a .bsp, and inside a pk3 with a texture and
// a shader script, written to the directory given on the command line.
#include <zip.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include "test_bsp.h"

int main(int argc, char** argv) {
    if (argc != 2) {
        std::fprintf(stderr, "usage: bsp_fuzz_seed DIR\n");
        return 2;
    }
    const std::filesystem::path dir = argv[1];
    std::filesystem::create_directories(dir);
    const std::vector<uint8_t> bsp = qvr::test::makeSampleBsp().bytes();
    std::ofstream((dir / "sample.bsp").string(), std::ios::binary)
        .write(reinterpret_cast<const char*>(bsp.data()), static_cast<std::streamsize>(bsp.size()));
    const std::vector<uint8_t> tga = qvr::test::makeTga(
        2, 2, {255, 0, 0, 255, 0, 255, 0, 255, 0, 0, 255, 255, 255, 255, 255, 255});
    const std::string shader =
        "textures/test/scripted\n{\n\t{\n\t\tmap textures/test/wall.tga\n\t}\n}\n";
    int err = 0;
    zip_t* z = zip_open((dir / "sample.pk3").string().c_str(), ZIP_CREATE | ZIP_TRUNCATE, &err);
    if (z == nullptr)
        return 1;
    zip_file_add(z, "maps/sample.bsp", zip_source_buffer(z, bsp.data(), bsp.size(), 0), 0);
    zip_file_add(z, "textures/test/wall.tga", zip_source_buffer(z, tga.data(), tga.size(), 0), 0);
    zip_file_add(z, "scripts/test.shader", zip_source_buffer(z, shader.data(), shader.size(), 0),
                 0);
    if (zip_close(z) != 0)
        return 1;
    std::printf("wrote %s/sample.bsp and sample.pk3\n", dir.string().c_str());
    return 0;
}
