#include "apps/text_file.h"

#include <filesystem>
#include <fstream>
#include <system_error>
#include <unistd.h>

namespace focal {

raster::Status writeTextFile(const std::string& path, const std::string& text) {
    namespace fs = std::filesystem;
    const fs::path target(path);
    const fs::path tmp = target.string() + ".tmp" + std::to_string(::getpid());
    {
        std::ofstream out(tmp, std::ios::binary);
        out << text;
        out.close();
        if (!out) {
            std::error_code ec;
            fs::remove(tmp, ec);
            return raster::Status::error(path + ": cannot write file");
        }
    }
    std::error_code ec;
    fs::rename(tmp, target, ec);
    if (ec) {
        fs::remove(tmp, ec);
        return raster::Status::error(path + ": cannot write file: " + ec.message());
    }
    return {};
}

} // namespace focal
