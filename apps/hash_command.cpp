#include "apps/hash_command.h"

#include "apps/image_io.h"
#include "apps/pixel_hash.h"

#include <algorithm>
#include <cctype>
#include <cstdio>

namespace focal {

CLI::App* addHashCommand(CLI::App& app, HashArgs& args) {
    CLI::App* cmd = app.add_subcommand(
        "hash", "Print a stable hash of each image's decoded pixels (docs/hash.md)");
    cmd->add_option("images", args.images, "image files (any format OpenImageIO reads)")
        ->required();
    cmd->add_option("--expect", args.expect,
                    "exit 1 unless the (single) image's hash is this one (16 hex digits)")
        ->check(CLI::Validator(
            [](const std::string& text) {
                const bool hex =
                    text.size() == 16 && std::all_of(text.begin(), text.end(), [](char c) {
                        return std::isxdigit(static_cast<unsigned char>(c)) != 0;
                    });
                return hex ? std::string() : "'" + text + "' is not 16 hex digits";
            },
            "HEX16"));
    return cmd;
}

int runHash(const HashArgs& args) {
    if (!args.expect.empty() && args.images.size() != 1) {
        std::fprintf(stderr, "focal: error: --expect takes exactly one image\n");
        return 2;
    }
    // Hash every image first, so a bad file never leaves half a listing on stdout.
    std::vector<std::string> lines;
    std::string hex;
    for (const std::string& path : args.images) {
        raster::Result<ImageSamples> image = readImageSamples(path);
        if (!image.ok()) {
            std::fprintf(stderr, "focal: error: %s\n", image.status().message().c_str());
            return 2;
        }
        hex = hashHex(pixelHash(*image));
        lines.push_back(hex + "  " + path);
    }
    for (const std::string& line : lines)
        std::printf("%s\n", line.c_str());
    if (args.expect.empty())
        return 0;
    std::string expect = args.expect;
    std::transform(expect.begin(), expect.end(), expect.begin(),
                   [](unsigned char c) { return char(std::tolower(c)); });
    if (hex == expect)
        return 0;
    std::fprintf(stderr, "focal: %s: hash %s, expected %s\n", args.images[0].c_str(), hex.c_str(),
                 expect.c_str());
    return 1;
}

} // namespace focal
