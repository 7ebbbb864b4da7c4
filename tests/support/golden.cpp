#include "support/golden.h"

#include "apps/image_io.h"
#include "support/test_util.h"

#include <raster/check.h>
#include <raster/texture.h>

#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <cinttypes>
#include <cstdio>
#include <cstdlib>
#include <fcntl.h>
#include <fstream>
#include <set>
#include <sstream>
#include <sys/file.h>
#include <system_error>
#include <unistd.h>

namespace focal::test {

namespace fs = std::filesystem;

namespace {

std::string hex(uint64_t v) {
    char buf[17];
    std::snprintf(buf, sizeof buf, "%016" PRIx64, v);
    return buf;
}

// An exclusive lock held for the lifetime of the object (flock on a file in the temp folder).
class FileLock {
public:
    explicit FileLock(const fs::path& path) {
        fd_ = ::open(path.c_str(), O_RDWR | O_CREAT, 0666);
        FOCAL_CHECK(fd_ >= 0);
        FOCAL_CHECK(::flock(fd_, LOCK_EX) == 0);
    }
    ~FileLock() {
        ::flock(fd_, LOCK_UN);
        ::close(fd_);
    }
    FileLock(const FileLock&) = delete;
    FileLock& operator=(const FileLock&) = delete;

private:
    int fd_ = -1;
};

struct Rgba8 {
    uint32_t width = 0;
    uint32_t height = 0;
    std::vector<uint8_t> bytes; // RGBA
};

bool readPng8(const fs::path& path, Rgba8& out, std::string& error) {
    return readPngRgba8(path, out.width, out.height, out.bytes, error);
}

// Writes 8-bit sRGB RGBA bytes through the application's PNG writer (which sRGB-encodes linear
// input), so the file is what `focal render -o NAME.png` would write for the same pixels.
void writePng8(const fs::path& path, uint32_t width, uint32_t height,
               const std::vector<uint8_t>& bytes);

} // namespace

bool readPngRgba8(const fs::path& path, uint32_t& width, uint32_t& height,
                  std::vector<uint8_t>& rgba, std::string& error) {
    std::error_code ec;
    if (!fs::exists(path, ec)) {
        error = path.string() + " does not exist";
        return false;
    }
    auto in = OIIO::ImageInput::open(path.string());
    if (!in) {
        error = path.string() + ": " + OIIO::geterror();
        return false;
    }
    const OIIO::ImageSpec& spec = in->spec();
    if (spec.nchannels != 4) {
        error = path.string() + ": expected 4 channels, found " + std::to_string(spec.nchannels);
        return false;
    }
    width = uint32_t(spec.width);
    height = uint32_t(spec.height);
    rgba.resize(size_t(width) * height * 4);
    if (!in->read_image(0, 0, 0, 4, OIIO::TypeDesc::UINT8, rgba.data())) {
        error = path.string() + ": " + in->geterror();
        return false;
    }
    return true;
}

namespace {

void writePng8(const fs::path& path, uint32_t width, uint32_t height,
               const std::vector<uint8_t>& bytes) {
    ImageData image{width, height, 4, std::vector<float>(bytes.size())};
    for (size_t i = 0; i < bytes.size(); ++i) {
        const float v = float(bytes[i]) / 255.0f;
        image.pixels[i] = i % 4 == 3 ? v : raster::srgbToLinear(v);
    }
    const raster::Status s = writeImage(path.string(), image);
    FOCAL_CHECK(s.ok());
}

void writeFramePng(const fs::path& path, const raster::Frame& frame) {
    const raster::Status s =
        writeImage(path.string(), ImageData{frame.width, frame.height, 4, frame.color});
    FOCAL_CHECK(s.ok());
}

struct ImageDiff {
    uint64_t differing = 0;      // pixels with any channel different
    uint64_t over_tolerance = 0; // pixels with a channel more than kGoldenImageTolerance off
    int max_diff = 0;            // largest channel difference, 8-bit steps
};

// Compares two same-sized RGBA8 images; fills `diff_rgba` with the false-colour diff image:
// equal pixels as the expected image dimmed to grey, differences within the tolerance blue,
// up to 16 steps yellow, more red.
ImageDiff compareRgba8(const std::vector<uint8_t>& expected, const std::vector<uint8_t>& actual,
                       std::vector<uint8_t>& diff_rgba) {
    ImageDiff d;
    diff_rgba.resize(expected.size());
    for (size_t p = 0; p < expected.size(); p += 4) {
        int m = 0;
        for (size_t c = 0; c < 4; ++c)
            m = std::max(m, std::abs(int(expected[p + c]) - int(actual[p + c])));
        d.max_diff = std::max(d.max_diff, m);
        d.differing += m > 0;
        d.over_tolerance += m > kGoldenImageTolerance;
        uint8_t r, g, b;
        if (m == 0) {
            r = g = b = uint8_t((2 * expected[p] + 5 * expected[p + 1] + expected[p + 2]) / 32);
        } else if (m <= kGoldenImageTolerance) {
            r = 40, g = 90, b = 255;
        } else if (m <= 16) {
            r = 255, g = 210, b = 0;
        } else {
            r = 255, g = 0, b = 0;
        }
        diff_rgba[p] = r, diff_rgba[p + 1] = g, diff_rgba[p + 2] = b, diff_rgba[p + 3] = 255;
    }
    return d;
}

// goldenDiffDir() without creating it.
fs::path diffDirPath() {
    const char* v = std::getenv("FOCAL_GOLDEN_DIFF_DIR");
    std::error_code ec;
    return fs::absolute(v && *v ? fs::path(v) : fs::current_path() / "golden-diff", ec);
}

} // namespace

std::string describeFrameDifference(const std::string& name, const raster::Frame& expected,
                                    const raster::Frame& actual) {
    std::ostringstream msg;
    const fs::path dir = goldenDiffDir();
    const fs::path actual_path = dir / (name + "_actual.png");
    writeFramePng(actual_path, actual);
    if (expected.width == actual.width && expected.height == actual.height) {
        std::vector<uint8_t> diff_rgba;
        const ImageDiff d = compareRgba8(toSrgb8(expected), toSrgb8(actual), diff_rgba);
        size_t float_pixels = 0;
        for (size_t i = 0; i < expected.color.size(); i += 4)
            float_pixels +=
                !std::equal(&expected.color[i], &expected.color[i] + 4, &actual.color[i]);
        const fs::path diff_path = dir / (name + "_diff.png");
        writePng8(diff_path, actual.width, actual.height, diff_rgba);
        msg << "  " << float_pixels << " pixels differ in the float colour, " << d.differing
            << " at 8 bits (max " << d.max_diff << " steps)\n";
        msg << "  actual: " << actual_path.string() << "\n";
        msg << "  diff:   " << diff_path.string()
            << " (grey: equal, blue: 1 step, yellow: <= 16 steps, red: more)\n";
    } else {
        msg << "  size " << actual.width << "x" << actual.height << " instead of " << expected.width
            << "x" << expected.height << "\n";
        msg << "  actual: " << actual_path.string() << "\n";
    }
    return msg.str();
}

bool updatingGoldens() {
    const char* v = std::getenv("FOCAL_UPDATE_GOLDENS");
    return v && *v && std::string(v) != "0";
}

const GoldenStore& pinholeGoldens() {
    static const GoldenStore store{
        fs::path(FOCAL_SOURCE_DIR) / "tests" / "golden",
        "64-bit FNV-1a of the colour floats and the stored depth of each\n"
        "# golden case (hashFrame in tests/support/test_util.h)"};
    return store;
}

const GoldenStore& dofGoldens() {
    static const GoldenStore store{
        fs::path(FOCAL_SOURCE_DIR) / "tests" / "golden" / "dof",
        "`focal hash` (docs/hash.md) of the EXR that `focal render`\n"
        "# writes for each golden case (tests/golden/dof_golden_test.cpp)"};
    return store;
}

fs::path goldenDiffDir() {
    const fs::path dir = diffDirPath();
    std::error_code ec;
    fs::create_directories(dir, ec);
    return dir;
}

std::map<std::string, uint64_t> readGoldenHashes(const fs::path& file,
                                                 std::vector<std::string>* errors) {
    std::map<std::string, uint64_t> hashes;
    std::ifstream in(file);
    std::string line;
    for (int line_no = 1; std::getline(in, line); ++line_no) {
        if (const size_t hash_pos = line.find('#'); hash_pos != std::string::npos)
            line.erase(hash_pos);
        std::istringstream fields(line);
        std::string name, value, extra;
        if (!(fields >> name))
            continue;
        char* end = nullptr;
        uint64_t h = 0;
        const bool ok = (fields >> value) && !(fields >> extra) && value.size() == 16 &&
                        (h = std::strtoull(value.c_str(), &end, 16), end == value.c_str() + 16);
        if (!ok || hashes.count(name)) {
            if (errors)
                errors->push_back(file.string() + ":" + std::to_string(line_no) + ": " +
                                  (ok ? "duplicate name " + name : "expected NAME HEX16"));
            continue;
        }
        hashes[name] = h;
    }
    return hashes;
}

void updateGoldenHashes(const GoldenStore& store, const std::map<std::string, uint64_t>& set,
                        const std::vector<std::string>& remove) {
    const FileLock lock(fs::temp_directory_path() / "focal-golden-hashes.lock");
    const fs::path file = store.hashFile();
    std::map<std::string, uint64_t> hashes = readGoldenHashes(file);
    for (const auto& [name, h] : set)
        hashes[name] = h;
    for (const std::string& name : remove)
        hashes.erase(name);
    std::ostringstream text;
    text << "# focal golden hashes: " << store.hash_definition
         << ", one 'NAME HEX' per line.\n"
            "# Compared exactly. Do not edit by hand; regenerate with\n"
            "#   "
         << kGoldenUpdateCommand << "\n# and read docs/testing.md first.\n";
    for (const auto& [name, h] : hashes)
        text << name << ' ' << hex(h) << '\n';
    fs::create_directories(file.parent_path());
    const fs::path tmp = file.string() + ".tmp" + std::to_string(::getpid());
    {
        std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
        out << text.str();
        out.close();
        FOCAL_CHECK(out.good());
    }
    fs::rename(tmp, file);
}

std::vector<uint8_t> toSrgb8(const raster::Frame& frame) {
    std::vector<uint8_t> bytes(frame.color.size());
    for (size_t i = 0; i < frame.color.size(); ++i) {
        const float v = frame.color[i];
        const float e = i % 4 == 3 ? v : raster::linearToSrgb(std::max(v, 0.0f));
        bytes[i] = uint8_t(std::clamp(e, 0.0f, 1.0f) * 255.0f + 0.5f);
    }
    return bytes;
}

::testing::AssertionResult matchesGolden(const GoldenStore& store, const std::string& name,
                                         const raster::Frame& frame, uint64_t actual_hash) {
    const std::vector<uint8_t> actual = toSrgb8(frame);
    const fs::path image_path = store.imagePath(name);

    if (updatingGoldens()) {
        updateGoldenHashes(store, {{name, actual_hash}});
        Rgba8 old;
        std::string error;
        fs::create_directories(image_path.parent_path());
        if (!readPng8(image_path, old, error) || old.width != frame.width ||
            old.height != frame.height || old.bytes != actual)
            writeFramePng(image_path, frame);
        std::printf("[golden] updated %s = %s\n", name.c_str(), hex(actual_hash).c_str());
        return ::testing::AssertionSuccess();
    }

    std::vector<std::string> errors;
    const std::map<std::string, uint64_t> hashes = readGoldenHashes(store.hashFile(), &errors);
    const auto it = hashes.find(name);
    const bool hash_ok = it != hashes.end() && it->second == actual_hash;

    Rgba8 golden;
    std::string image_error;
    bool image_ok = readPng8(image_path, golden, image_error);
    if (image_ok && (golden.width != frame.width || golden.height != frame.height)) {
        image_error = image_path.string() + " is " + std::to_string(golden.width) + "x" +
                      std::to_string(golden.height) + ", the render is " +
                      std::to_string(frame.width) + "x" + std::to_string(frame.height);
        image_ok = false;
    }
    ImageDiff diff;
    std::vector<uint8_t> diff_rgba;
    if (image_ok) {
        diff = compareRgba8(golden.bytes, actual, diff_rgba);
        image_ok = diff.over_tolerance == 0;
    }
    if (hash_ok && image_ok) {
        // Drop the files of an earlier failing run, so golden-diff/ shows only current failures.
        std::error_code ec;
        fs::remove(diffDirPath() / (name + "_actual.png"), ec);
        fs::remove(diffDirPath() / (name + "_diff.png"), ec);
        return ::testing::AssertionSuccess();
    }

    // Report: what differs, and where to look.
    std::ostringstream msg;
    msg << "golden '" << name << "' does not match.\n";
    for (const std::string& e : errors)
        msg << "  " << e << "\n";
    if (it == hashes.end())
        msg << "  hash: no entry for '" << name << "' in " << store.hashFile().string() << "\n";
    else if (!hash_ok)
        msg << "  hash: expected " << hex(it->second) << ", got " << hex(actual_hash)
            << " (the colour, or a pinhole golden's stored depth, changed)\n";
    if (!image_error.empty()) {
        msg << "  image: " << image_error << "\n";
    } else {
        msg << "  image: " << diff.differing << " of " << size_t(frame.width) * frame.height
            << " pixels differ at 8 bits, " << diff.over_tolerance << " by more than "
            << kGoldenImageTolerance << " step (max " << diff.max_diff << ")"
            << (diff.differing == 0 ? "; the change is below 8-bit precision or in depth" : "")
            << "\n";
    }
    const fs::path dir = goldenDiffDir();
    const fs::path actual_path = dir / (name + "_actual.png");
    writeFramePng(actual_path, frame);
    msg << "  actual:   " << actual_path.string() << "\n";
    msg << "  expected: " << image_path.string() << "\n";
    if (!diff_rgba.empty()) {
        const fs::path diff_path = dir / (name + "_diff.png");
        writePng8(diff_path, frame.width, frame.height, diff_rgba);
        msg << "  diff:     " << diff_path.string()
            << " (grey: equal, blue: within tolerance, yellow: <= 16 steps, red: more)\n";
    }
    msg << "  If the change to the pixels is intended, regenerate with " << kGoldenUpdateCommand
        << " and say why in the commit (docs/testing.md).";
    return ::testing::AssertionFailure() << msg.str();
}

::testing::AssertionResult
variantsDiffer(const GoldenStore& store,
               std::span<const std::pair<const char*, const char*>> pairs) {
    const std::map<std::string, uint64_t> hashes = readGoldenHashes(store.hashFile());
    std::ostringstream msg;
    for (const auto& [a, b] : pairs) {
        if (!hashes.count(a) || !hashes.count(b))
            msg << "no golden hash for " << a << " or " << b << "\n";
        else if (hashes.at(a) == hashes.at(b))
            msg << a << " and " << b << " render the same bits\n";
    }
    if (msg.str().empty())
        return ::testing::AssertionSuccess();
    return ::testing::AssertionFailure() << msg.str();
}

::testing::AssertionResult holdsExactly(const GoldenStore& store,
                                        const std::vector<std::string>& names) {
    const std::set<std::string> known(names.begin(), names.end());
    std::vector<std::string> errors;
    const auto hashes = readGoldenHashes(store.hashFile(), &errors);
    std::vector<std::string> stale_hashes;
    for (const auto& [name, h] : hashes)
        if (!known.count(name))
            stale_hashes.push_back(name);
    std::vector<fs::path> stale_images;
    std::error_code ec;
    for (const fs::directory_entry& e : fs::directory_iterator(store.dir / "images", ec))
        if (e.path().extension() != ".png" || !known.count(e.path().stem().string()))
            stale_images.push_back(e.path());

    if (updatingGoldens()) {
        updateGoldenHashes(store, {}, stale_hashes);
        for (const fs::path& p : stale_images)
            fs::remove(p, ec);
        return ::testing::AssertionSuccess();
    }
    std::ostringstream msg;
    for (const std::string& e : errors)
        msg << e << "\n";
    for (const std::string& name : stale_hashes)
        msg << store.hashFile().string() << ": entry '" << name << "' has no case\n";
    for (const fs::path& p : stale_images)
        msg << p.string() << ": no case of that name\n";
    for (const std::string& name : known) {
        if (!hashes.count(name))
            msg << "no golden hash for " << name << " in " << store.hashFile().string() << "\n";
        if (!fs::exists(store.imagePath(name), ec))
            msg << "no golden image " << store.imagePath(name).string() << "\n";
    }
    if (msg.str().empty())
        return ::testing::AssertionSuccess();
    return ::testing::AssertionFailure() << msg.str() << "run " << kGoldenUpdateCommand;
}

} // namespace focal::test
