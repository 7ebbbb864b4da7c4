// glTF 2.0 import: tinygltf parses the JSON (and GLB container) into its Model; everything read
// from that Model is validated here and converted into focal's Scene at once. Nothing escapes this
// file as an exception: tinygltf (nlohmann json) may throw, so the whole import runs under a
// catch-all that turns any throw into a Status, and each image-decoding task (which may run on a
// worker thread) catches its own. Only the images the caller's texture roles need are decoded.
#include "stopwatch.h"

#include <raster/gltf_import.h>

#include <glm/geometric.hpp>
#include <glm/mat3x3.hpp>
#include <glm/mat4x4.hpp>
#include <tiny_gltf.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <exception>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <new>
#include <set>
#include <string>
#include <utility>
#include <vector>

namespace raster {
namespace {

#define FOCAL_GLTF_TRY(expr)                                                                       \
    do {                                                                                           \
        Status focal_gltf_status_ = (expr);                                                        \
        if (!focal_gltf_status_.ok())                                                              \
            return focal_gltf_status_;                                                             \
    } while (0)

// Limits on what a file may make us allocate: images up to 32768 pixels a side and 2^27 pixels
// (512 MiB as RGBA8); accessors without a bufferView (all zeros) up to 2^24 elements each, and
// in all (every read counts: 16 primitives sharing one such accessor read it 16 times) at most
// 256 elements per byte the file and its buffers hold, or 2^20 for small files. A zero element
// costs the import up to 8 bytes per component, so a 300-byte file can no longer ask for GBs.
constexpr uint32_t kMaxImageSide = 32768;
constexpr uint64_t kMaxImagePixels = uint64_t{1} << 27;
constexpr size_t kMaxZeroAccessorCount = size_t{1} << 24;
constexpr uint64_t kZeroElementsPerSourceByte = 256;
constexpr uint64_t kMinZeroElementsPerFile = uint64_t{1} << 20;
// JSON nesting focal parses: glTF itself needs about 8 levels, extras a few more. The JSON
// parser recurses once per level, so a file nested 15,000 deep overflowed the stack.
constexpr size_t kMaxJsonDepth = 128;

// Extensions focal implements fully; a file may require any of them.
constexpr const char* kSupportedExtensions[] = {
    "KHR_texture_transform", "KHR_materials_unlit", "KHR_lights_punctual",
    "KHR_materials_emissive_strength", "KHR_mesh_quantization"};

bool isSupportedExtension(const std::string& name) {
    return std::any_of(std::begin(kSupportedExtensions), std::end(kSupportedExtensions),
                       [&](const char* s) { return name == s; });
}

// First non-empty line of a (possibly multi-line) message, trimmed; for tinygltf's err/warn.
std::string firstLine(const std::string& text) {
    size_t pos = 0;
    while (pos < text.size()) {
        size_t end = text.find('\n', pos);
        if (end == std::string::npos)
            end = text.size();
        std::string line = text.substr(pos, end - pos);
        while (!line.empty() && (line.back() == '\r' || line.back() == ' ' || line.back() == '\t'))
            line.pop_back();
        size_t start = line.find_first_not_of(" \t");
        if (start != std::string::npos)
            return line.substr(start);
        pos = end + 1;
    }
    return {};
}

std::vector<std::string> lines(const std::string& text) {
    std::vector<std::string> out;
    size_t pos = 0;
    while (pos < text.size()) {
        size_t end = text.find('\n', pos);
        if (end == std::string::npos)
            end = text.size();
        std::string line = firstLine(text.substr(pos, end - pos));
        if (!line.empty())
            out.push_back(std::move(line));
        pos = end + 1;
    }
    return out;
}

// Width and height from a PNG or JPEG header, so absurd sizes are refused before stb_image tries
// to allocate them. Returns false when the header is not recognised (stb then decides).
bool peekImageSize(const unsigned char* p, size_t n, uint32_t& width, uint32_t& height) {
    auto be16 = [&](size_t at) { return static_cast<uint32_t>(p[at] << 8 | p[at + 1]); };
    auto be32 = [&](size_t at) { return be16(at) << 16 | be16(at + 2); };
    static const unsigned char kPng[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
    if (n >= 24 && std::memcmp(p, kPng, 8) == 0 &&
        std::memcmp(p + 12, "IHDR", 4) == 0) { // IHDR is the first chunk
        width = be32(16);
        height = be32(20);
        return true;
    }
    if (n >= 4 && p[0] == 0xFF && p[1] == 0xD8) { // JPEG: walk the markers to a SOFn
        size_t at = 2;
        while (at + 9 < n) {
            if (p[at] != 0xFF)
                return false;
            const unsigned char marker = p[at + 1];
            if (marker >= 0xC0 && marker <= 0xCF && marker != 0xC4 && marker != 0xC8 &&
                marker != 0xCC) {
                height = be16(at + 5);
                width = be16(at + 7);
                return true;
            }
            at += 2 + be16(at + 2);
        }
    }
    return false;
}

bool startsWith(const std::string& s, const char* prefix) {
    return s.rfind(prefix, 0) == 0;
}

// Image bytes captured by our tinygltf image-loader callback. tinygltf hands us the encoded bytes
// of images with a uri (data URI or external file); images in a bufferView are read (and
// range-checked) by us afterwards, because tinygltf does not check the bufferView's range.
struct CapturedImages {
    std::vector<std::vector<unsigned char>> bytes; // by image index
    std::vector<bool> delivered;
};

bool captureImage(tinygltf::Image* image, const int image_idx, std::string* err, std::string*, int,
                  int, const unsigned char* bytes, int size, void* user_data) {
    try {
        auto* captured = static_cast<CapturedImages*>(user_data);
        if (image_idx < 0 || size < 0)
            return false;
        const size_t idx = static_cast<size_t>(image_idx);
        if (captured->bytes.size() <= idx) {
            captured->bytes.resize(idx + 1);
            captured->delivered.resize(idx + 1, false);
        }
        captured->delivered[idx] = true;
        if (image->bufferView < 0 && bytes != nullptr && size > 0)
            captured->bytes[idx].assign(bytes, bytes + size);
        return true;
    } catch (...) {
        if (err)
            *err += "out of memory while reading image " + std::to_string(image_idx) + "\n";
        return false;
    }
}

size_t componentSize(int component_type) {
    switch (component_type) {
    case TINYGLTF_COMPONENT_TYPE_BYTE:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
        return 1;
    case TINYGLTF_COMPONENT_TYPE_SHORT:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT:
        return 2;
    case TINYGLTF_COMPONENT_TYPE_INT:
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT:
    case TINYGLTF_COMPONENT_TYPE_FLOAT:
        return 4;
    default:
        return 0;
    }
}

const char* componentName(int component_type) {
    switch (component_type) {
    case TINYGLTF_COMPONENT_TYPE_BYTE:
        return "BYTE";
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE:
        return "UNSIGNED_BYTE";
    case TINYGLTF_COMPONENT_TYPE_SHORT:
        return "SHORT";
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT:
        return "UNSIGNED_SHORT";
    case TINYGLTF_COMPONENT_TYPE_INT:
        return "INT";
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT:
        return "UNSIGNED_INT";
    case TINYGLTF_COMPONENT_TYPE_FLOAT:
        return "FLOAT";
    default:
        return "unknown";
    }
}

int componentCount(int type) {
    switch (type) {
    case TINYGLTF_TYPE_SCALAR:
        return 1;
    case TINYGLTF_TYPE_VEC2:
        return 2;
    case TINYGLTF_TYPE_VEC3:
        return 3;
    case TINYGLTF_TYPE_VEC4:
        return 4;
    case TINYGLTF_TYPE_MAT2:
        return 4;
    case TINYGLTF_TYPE_MAT3:
        return 9;
    case TINYGLTF_TYPE_MAT4:
        return 16;
    default:
        return 0;
    }
}

const char* typeName(int type) {
    switch (type) {
    case TINYGLTF_TYPE_SCALAR:
        return "SCALAR";
    case TINYGLTF_TYPE_VEC2:
        return "VEC2";
    case TINYGLTF_TYPE_VEC3:
        return "VEC3";
    case TINYGLTF_TYPE_VEC4:
        return "VEC4";
    case TINYGLTF_TYPE_MAT2:
        return "MAT2";
    case TINYGLTF_TYPE_MAT3:
        return "MAT3";
    case TINYGLTF_TYPE_MAT4:
        return "MAT4";
    default:
        return "unknown";
    }
}

// One component at p (no alignment assumed: buffer bytes are read with memcpy). Normalized
// integers map to [0,1] / [-1,1] as glTF 2.0 §3.11 ("Animations" / accessor normalization) says.
double readComponent(const unsigned char* p, int component_type, bool normalized) {
    switch (component_type) {
    case TINYGLTF_COMPONENT_TYPE_BYTE: {
        int8_t v;
        std::memcpy(&v, p, 1);
        return normalized ? std::max(v / 127.0, -1.0) : v;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: {
        uint8_t v;
        std::memcpy(&v, p, 1);
        return normalized ? v / 255.0 : v;
    }
    case TINYGLTF_COMPONENT_TYPE_SHORT: {
        int16_t v;
        std::memcpy(&v, p, 2);
        return normalized ? std::max(v / 32767.0, -1.0) : v;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
        uint16_t v;
        std::memcpy(&v, p, 2);
        return normalized ? v / 65535.0 : v;
    }
    case TINYGLTF_COMPONENT_TYPE_INT: {
        int32_t v;
        std::memcpy(&v, p, 4);
        return v;
    }
    case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: {
        uint32_t v;
        std::memcpy(&v, p, 4);
        return normalized ? v / 4294967295.0 : v;
    }
    case TINYGLTF_COMPONENT_TYPE_FLOAT: {
        float v;
        std::memcpy(&v, p, 4);
        return static_cast<double>(v);
    }
    default:
        return 0.0;
    }
}

// a + b, or false on overflow.
bool addSize(size_t a, size_t b, size_t& out) {
    if (a > std::numeric_limits<size_t>::max() - b)
        return false;
    out = a + b;
    return true;
}

bool mulSize(size_t a, size_t b, size_t& out) {
    if (a != 0 && b > std::numeric_limits<size_t>::max() / a)
        return false;
    out = a * b;
    return true;
}

// Which component types an attribute may use (glTF 2.0 §3.7.2.1, plus KHR_mesh_quantization).
struct AttributeRule {
    const char* name;
    std::vector<int> types; // TINYGLTF_TYPE_*
    struct Component {
        int type;
        bool normalized_allowed;
        bool unnormalized_allowed;
    };
    std::vector<Component> components;
};

class Importer {
public:
    // source_bytes: the size of the file and its buffers, which bounds what it may allocate.
    Importer(std::string path, tinygltf::Model& model, Scene& scene, const ImportOptions& options,
             ImportStats& stats, uint64_t source_bytes)
        : path_(std::move(path)), model_(model), scene_(scene), options_(options), stats_(stats),
          source_bytes_(source_bytes),
          zero_element_limit_(std::max(kMinZeroElementsPerFile,
                                       mulBytes(source_bytes, kZeroElementsPerSourceByte))) {}

    Status run(const CapturedImages& captured);

private:
    Status fail(const std::string& what) const { return Status::error(path_ + ": " + what); }
    void warn(std::string what) { scene_.warnings.push_back(std::move(what)); }

    Status checkExtensions();
    Status convertSamplers();
    Status convertImages(const CapturedImages& captured);
    Status textureRef(const tinygltf::TextureInfo& info, const std::string& what, TextureRef& out);
    Status convertMaterials();
    Status convertMeshes();
    Status convertPrimitive(size_t mesh_index, size_t prim_index, const tinygltf::Primitive& in,
                            Primitive& out, bool& keep);
    Status accessorValues(int index, const std::string& what, const AttributeRule* rule,
                          std::vector<double>& out, int& components);
    Status bufferViewBytes(int index, const std::string& what, const unsigned char*& data,
                           size_t& size);
    Status checkNodeGraph();
    Status localMatrix(size_t node_index, glm::mat4& out);
    Status convertNodes();
    Status placeCamera(size_t node_index, const glm::mat4& world);
    Status placeLight(size_t node_index, const tinygltf::Value& ext, const glm::mat4& world);

    std::string path_;
    tinygltf::Model& model_;
    Scene& scene_;
    bool quantization_ = false;
    const ImportOptions& options_;
    ImportStats& stats_;
    uint64_t source_bytes_ = 0;
    uint64_t zero_element_limit_ = 0;
    uint64_t zero_elements_ = 0;    // elements read from accessors without a bufferView so far
    uint64_t zero_value_bytes_ = 0; // and the bytes their values took
};

Status Importer::checkExtensions() {
    scene_.extensions_used = model_.extensionsUsed;
    scene_.extensions_required = model_.extensionsRequired;
    for (const std::string& ext : model_.extensionsRequired) {
        if (!isSupportedExtension(ext))
            return fail("required extension " + ext + " is not supported");
    }
    for (const std::string& ext : model_.extensionsUsed) {
        if (ext == "KHR_mesh_quantization")
            quantization_ = true;
        if (!isSupportedExtension(ext))
            warn("extension " + ext + " is not supported; ignored");
    }
    return {};
}

Status Importer::convertSamplers() {
    for (size_t i = 0; i < model_.samplers.size(); ++i) {
        const tinygltf::Sampler& in = model_.samplers[i];
        const std::string what = "sampler " + std::to_string(i);
        Sampler out;
        auto wrap = [&](int mode, const char* axis, Wrap& w) -> Status {
            switch (mode) {
            case TINYGLTF_TEXTURE_WRAP_REPEAT:
                w = Wrap::Repeat;
                return {};
            case TINYGLTF_TEXTURE_WRAP_CLAMP_TO_EDGE:
                w = Wrap::ClampToEdge;
                return {};
            case TINYGLTF_TEXTURE_WRAP_MIRRORED_REPEAT:
                w = Wrap::MirroredRepeat;
                return {};
            default:
                return fail(what + " has an unknown " + axis + " " + std::to_string(mode));
            }
        };
        FOCAL_GLTF_TRY(wrap(in.wrapS, "wrapS", out.wrap_s));
        FOCAL_GLTF_TRY(wrap(in.wrapT, "wrapT", out.wrap_t));
        // Undefined filters (-1) default to linear / linear-mipmap-linear.
        switch (in.magFilter) {
        case -1:
        case TINYGLTF_TEXTURE_FILTER_LINEAR:
            out.mag = Filter::Linear;
            break;
        case TINYGLTF_TEXTURE_FILTER_NEAREST:
            out.mag = Filter::Nearest;
            break;
        default:
            return fail(what + " has an unknown magFilter " + std::to_string(in.magFilter));
        }
        switch (in.minFilter) {
        case -1:
        case TINYGLTF_TEXTURE_FILTER_LINEAR_MIPMAP_LINEAR:
            out.min = Filter::Linear;
            out.mip = MipFilter::Linear;
            break;
        case TINYGLTF_TEXTURE_FILTER_NEAREST:
            out.min = Filter::Nearest;
            out.mip = MipFilter::None;
            break;
        case TINYGLTF_TEXTURE_FILTER_LINEAR:
            out.min = Filter::Linear;
            out.mip = MipFilter::None;
            break;
        case TINYGLTF_TEXTURE_FILTER_NEAREST_MIPMAP_NEAREST:
            out.min = Filter::Nearest;
            out.mip = MipFilter::Nearest;
            break;
        case TINYGLTF_TEXTURE_FILTER_LINEAR_MIPMAP_NEAREST:
            out.min = Filter::Linear;
            out.mip = MipFilter::Nearest;
            break;
        case TINYGLTF_TEXTURE_FILTER_NEAREST_MIPMAP_LINEAR:
            out.min = Filter::Nearest;
            out.mip = MipFilter::Linear;
            break;
        default:
            return fail(what + " has an unknown minFilter " + std::to_string(in.minFilter));
        }
        scene_.samplers.push_back(out);
    }
    return {};
}

Status Importer::bufferViewBytes(int index, const std::string& what, const unsigned char*& data,
                                 size_t& size) {
    if (index < 0 || static_cast<size_t>(index) >= model_.bufferViews.size())
        return fail(what + " refers to bufferView " + std::to_string(index) + ", but there are " +
                    std::to_string(model_.bufferViews.size()));
    const tinygltf::BufferView& view = model_.bufferViews[static_cast<size_t>(index)];
    const std::string view_name = "bufferView " + std::to_string(index);
    if (view.buffer < 0 || static_cast<size_t>(view.buffer) >= model_.buffers.size())
        return fail(view_name + " refers to buffer " + std::to_string(view.buffer) +
                    ", but there are " + std::to_string(model_.buffers.size()));
    const tinygltf::Buffer& buffer = model_.buffers[static_cast<size_t>(view.buffer)];
    size_t end = 0;
    if (!addSize(view.byteOffset, view.byteLength, end) || end > buffer.data.size())
        return fail(view_name + " reads past the end of buffer " + std::to_string(view.buffer) +
                    " (" + std::to_string(view.byteOffset) + " + " +
                    std::to_string(view.byteLength) + " > " + std::to_string(buffer.data.size()) +
                    " bytes)");
    data = buffer.data.data() + view.byteOffset;
    size = view.byteLength;
    return {};
}

// One image on its way from encoded bytes to a mip chain. decodeImage writes only its own slot,
// so images decode on any worker in any order and the result is the same for any thread count.
struct ImageSlot {
    std::string what; // "image 3 (name)", for messages
    Status fatal;     // a broken file (bytes out of range): reported in image order
    const unsigned char* bytes = nullptr;
    size_t size = 0;
    bool needed = false; // used in a role the caller asked for: decode it
    std::string problem; // why the image has no pixels; empty when it decoded
    Image image;
    double ms_decode = 0.0;
    double ms_mipmaps = 0.0;
    const char* thrown = nullptr; // decoding threw (no allocation in the handler): this says what
};

// Decodes slot.bytes into slot.image (8-bit RGBA, full mip chain), or sets slot.problem.
// Thread-safe: stb_image keeps its error state per thread, and nothing else is shared.
void decodeImage(ImageSlot& slot, int index) {
    // Decode with stb_image (inside libtinygltf), forcing 4 channels (grey, grey-alpha and RGB
    // are expanded); 16-bit images stay 16-bit and are reduced below.
    auto t0 = std::chrono::steady_clock::now();
    tinygltf::Image decoded;
    std::string err, warn_text;
    if (!tinygltf::LoadImageData(&decoded, index, &err, &warn_text, 0, 0, slot.bytes,
                                 static_cast<int>(slot.size), nullptr)) {
        slot.problem = "cannot be decoded (not a PNG/JPEG/BMP/GIF/TGA/PSD/HDR/PNM image stb can "
                       "read)";
        return;
    }
    const size_t bytes_per = decoded.bits == 16 ? 2 : 1;
    size_t texels = 0, expect = 0;
    if (decoded.width < 1 || decoded.height < 1 || decoded.component != 4 ||
        (decoded.bits != 8 && decoded.bits != 16) ||
        !mulSize(static_cast<size_t>(decoded.width), static_cast<size_t>(decoded.height), texels) ||
        !mulSize(texels, 4 * bytes_per, expect) || decoded.image.size() != expect) {
        slot.problem = "decoded to an unexpected pixel layout";
        return;
    }
    MipLevel level;
    level.width = static_cast<uint32_t>(decoded.width);
    level.height = static_cast<uint32_t>(decoded.height);
    if (decoded.bits == 8) {
        level.rgba8 = std::move(decoded.image);
    } else {
        // 16 → 8 bit with rounding: v8 = round(v16 * 255 / 65535).
        level.rgba8.resize(texels * 4);
        for (size_t k = 0; k < texels * 4; ++k) {
            uint16_t v;
            std::memcpy(&v, decoded.image.data() + 2 * k, 2);
            level.rgba8[k] = static_cast<uint8_t>((uint32_t{v} * 255u + 32767u) / 65535u);
        }
    }
    slot.image.levels.push_back(std::move(level));
    slot.ms_decode = msSince(t0);

    t0 = std::chrono::steady_clock::now();
    buildMipChain(slot.image);
    slot.ms_mipmaps = msSince(t0);
}

Status Importer::convertImages(const CapturedImages& captured) {
    // What each image is used for. Base colour and emissive colour a surface: they are sRGB,
    // and a needed one that does not decode fails the import.
    const size_t count = model_.images.size();
    std::vector<TextureRoles> roles(count);
    auto mark = [&](int texture, TextureRole role) {
        if (texture < 0 || static_cast<size_t>(texture) >= model_.textures.size())
            return; // reported by convertMaterials
        const int source = model_.textures[static_cast<size_t>(texture)].source;
        if (source >= 0 && static_cast<size_t>(source) < count)
            roles[static_cast<size_t>(source)] = roles[static_cast<size_t>(source)] | role;
    };
    for (const tinygltf::Material& m : model_.materials) {
        mark(m.pbrMetallicRoughness.baseColorTexture.index, TextureRole::BaseColor);
        mark(m.emissiveTexture.index, TextureRole::Emissive);
        mark(m.pbrMetallicRoughness.metallicRoughnessTexture.index, TextureRole::MetallicRoughness);
        mark(m.normalTexture.index, TextureRole::Normal);
        mark(m.occlusionTexture.index, TextureRole::Occlusion);
    }
    const TextureRoles colour = TextureRoles{} | TextureRole::BaseColor | TextureRole::Emissive;

    // Find the encoded bytes and check what needs no decoding, in image order.
    std::vector<ImageSlot> slots(count);
    for (size_t i = 0; i < count; ++i) {
        const tinygltf::Image& in = model_.images[i];
        ImageSlot& slot = slots[i];
        slot.what = "image " + std::to_string(i);
        if (!in.name.empty())
            slot.what += " (" + in.name + ")";
        else if (!in.uri.empty() && !tinygltf::IsDataURI(in.uri))
            slot.what += " (" + in.uri + ")";
        slot.image.name = in.name.empty() ? in.uri : in.name;
        if (tinygltf::IsDataURI(slot.image.name))
            slot.image.name = "image " + std::to_string(i);
        slot.image.roles = roles[i];
        slot.image.srgb = roles[i].intersects(colour);
        slot.needed = !options_.roles || roles[i].intersects(*options_.roles);

        if (in.bufferView >= 0) {
            slot.fatal = bufferViewBytes(in.bufferView, slot.what, slot.bytes, slot.size);
            if (!slot.fatal.ok())
                continue;
        } else if (i < captured.delivered.size() && captured.delivered[i]) {
            slot.bytes = captured.bytes[i].data();
            slot.size = captured.bytes[i].size();
        } else {
            slot.problem = "file not found: " + in.uri;
        }
        if (slot.problem.empty() && slot.size == 0)
            slot.problem = "is empty";
        if (slot.problem.empty() &&
            slot.size > static_cast<size_t>(std::numeric_limits<int>::max()))
            slot.problem = "is too large to decode";
        uint32_t header_w = 0, header_h = 0;
        if (slot.problem.empty() && peekImageSize(slot.bytes, slot.size, header_w, header_h) &&
            (header_w > kMaxImageSide || header_h > kMaxImageSide ||
             uint64_t{header_w} * header_h > kMaxImagePixels))
            slot.problem =
                "is too large (" + std::to_string(header_w) + "x" + std::to_string(header_h) + ")";
    }

    // Decode and mipmap the needed images, one image per task.
    const auto t0 = std::chrono::steady_clock::now();
    auto decodeOne = [&](uint32_t i, uint32_t) {
        ImageSlot& slot = slots[i];
        if (!slot.needed || !slot.fatal.ok() || !slot.problem.empty())
            return;
        // Nothing may escape a task (it would end the worker thread): note what was thrown.
        try {
            decodeImage(slot, static_cast<int>(i));
        } catch (const std::bad_alloc&) {
            slot.thrown = "out of memory while decoding";
        } catch (...) {
            slot.thrown = "decoding failed";
        }
    };
    const uint32_t count32 = static_cast<uint32_t>(count);
    if (options_.pool)
        options_.pool->parallelFor(count32, decodeOne);
    else
        for (uint32_t i = 0; i < count32; ++i)
            decodeOne(i, 0);
    stats_.ms_images = msSince(t0);

    // Report and keep the results in image order.
    for (size_t i = 0; i < count; ++i) {
        ImageSlot& slot = slots[i];
        if (!slot.fatal.ok())
            return slot.fatal;
        if (slot.thrown)
            return fail(slot.what + " " + slot.thrown);
        stats_.ms_decode += slot.ms_decode;
        stats_.ms_mipmaps += slot.ms_mipmaps;
        Image& out = slot.image;
        if (!slot.needed) {
            // Not sampled: left without pixels; what was found without decoding is reported.
            if (!slot.problem.empty())
                warn(slot.what + " " + slot.problem + "; not needed, so not decoded");
            out.decoded = false;
            ++stats_.images_skipped;
        } else if (!slot.problem.empty()) {
            if (out.srgb)
                return fail(slot.what + " " + slot.problem);
            // Not used for colour: keep a 1x1 white placeholder so indices stay valid.
            warn(slot.what + " " + slot.problem + "; replaced by a white texel");
            MipLevel level;
            level.width = 1;
            level.height = 1;
            level.rgba8.assign(4, 255);
            out.levels.push_back(std::move(level));
        } else {
            ++stats_.images_decoded;
        }
        scene_.images.push_back(std::move(out));
    }
    return {};
}

// Reads a JSON array of numbers of exactly `n` finite entries.
bool numberArray(const tinygltf::Value& v, size_t n, double* out) {
    if (!v.IsArray() || v.ArrayLen() != n)
        return false;
    for (size_t i = 0; i < n; ++i) {
        const tinygltf::Value& e = v.Get(static_cast<int>(i));
        if (!e.IsNumber() || !std::isfinite(e.GetNumberAsDouble()))
            return false;
        out[i] = e.GetNumberAsDouble();
    }
    return true;
}

Status Importer::textureRef(const tinygltf::TextureInfo& info, const std::string& what,
                            TextureRef& out) {
    out = TextureRef{};
    if (info.index < 0)
        return {};
    if (static_cast<size_t>(info.index) >= model_.textures.size())
        return fail(what + " refers to texture " + std::to_string(info.index) + ", but there are " +
                    std::to_string(model_.textures.size()));
    const tinygltf::Texture& tex = model_.textures[static_cast<size_t>(info.index)];
    const std::string tex_name = "texture " + std::to_string(info.index);
    if (tex.sampler >= 0 && static_cast<size_t>(tex.sampler) >= model_.samplers.size())
        return fail(tex_name + " refers to sampler " + std::to_string(tex.sampler) +
                    ", but there are " + std::to_string(model_.samplers.size()));
    if (tex.source >= 0 && static_cast<size_t>(tex.source) >= model_.images.size())
        return fail(tex_name + " refers to image " + std::to_string(tex.source) +
                    ", but there are " + std::to_string(model_.images.size()));
    if (tex.source < 0) {
        warn(what + " uses " + tex_name + ", which has no image focal can read; drawn untextured");
        return {};
    }
    if (info.texCoord < 0)
        return fail(what + " has a negative texCoord");
    out.image = tex.source;
    out.sampler = tex.sampler;
    out.texcoord = static_cast<uint32_t>(info.texCoord);

    // KHR_texture_transform: uv' = T * R * S * uv (extension README, "Overview"), where the
    // GLSL there builds R = mat3(cos, sin, 0, -sin, cos, 0, 0, 0, 1) column by column.
    auto it = info.extensions.find("KHR_texture_transform");
    if (it != info.extensions.end()) {
        const tinygltf::Value& ext = it->second;
        if (!ext.IsObject())
            return fail(what + ": KHR_texture_transform is not an object");
        double offset[2] = {0.0, 0.0}, scale[2] = {1.0, 1.0}, rotation = 0.0;
        if (ext.Has("offset") && !numberArray(ext.Get("offset"), 2, offset))
            return fail(what + ": KHR_texture_transform offset is not two finite numbers");
        if (ext.Has("scale") && !numberArray(ext.Get("scale"), 2, scale))
            return fail(what + ": KHR_texture_transform scale is not two finite numbers");
        if (ext.Has("rotation")) {
            const tinygltf::Value& r = ext.Get("rotation");
            if (!r.IsNumber() || !std::isfinite(r.GetNumberAsDouble()))
                return fail(what + ": KHR_texture_transform rotation is not a finite number");
            rotation = r.GetNumberAsDouble();
        }
        if (ext.Has("texCoord")) {
            const tinygltf::Value& t = ext.Get("texCoord");
            if (!t.IsInt() || t.GetNumberAsInt() < 0)
                return fail(what + ": KHR_texture_transform texCoord is not a non-negative "
                                   "integer");
            out.texcoord = static_cast<uint32_t>(t.GetNumberAsInt());
        }
        const float c = static_cast<float>(std::cos(rotation));
        const float s = static_cast<float>(std::sin(rotation));
        const glm::mat3 t(1, 0, 0, 0, 1, 0, static_cast<float>(offset[0]),
                          static_cast<float>(offset[1]), 1);
        const glm::mat3 r(c, s, 0, -s, c, 0, 0, 0, 1);
        const glm::mat3 sc(static_cast<float>(scale[0]), 0, 0, 0, static_cast<float>(scale[1]), 0,
                           0, 0, 1);
        out.transform = t * r * sc;
    }
    if (out.texcoord != 0)
        warn(what + " uses TEXCOORD_" + std::to_string(out.texcoord) +
             "; focal reads only TEXCOORD_0");
    return {};
}

Status Importer::convertMaterials() {
    for (size_t i = 0; i < model_.materials.size(); ++i) {
        const tinygltf::Material& in = model_.materials[i];
        const std::string what = "material " + std::to_string(i);
        Material out;
        out.name = in.name;
        const tinygltf::PbrMetallicRoughness& pbr = in.pbrMetallicRoughness;
        if (pbr.baseColorFactor.size() != 4)
            return fail(what + " baseColorFactor does not have 4 entries");
        for (int k = 0; k < 4; ++k) {
            const double v = pbr.baseColorFactor[static_cast<size_t>(k)];
            if (!std::isfinite(v))
                return fail(what + " baseColorFactor is not finite");
            out.base_color_factor[k] = static_cast<float>(v);
        }
        if (in.emissiveFactor.size() != 3)
            return fail(what + " emissiveFactor does not have 3 entries");
        for (int k = 0; k < 3; ++k) {
            const double v = in.emissiveFactor[static_cast<size_t>(k)];
            if (!std::isfinite(v))
                return fail(what + " emissiveFactor is not finite");
            out.emissive_factor[k] = static_cast<float>(v);
        }
        if (!std::isfinite(pbr.metallicFactor) || !std::isfinite(pbr.roughnessFactor))
            return fail(what + " metallicFactor or roughnessFactor is not finite");
        out.metallic_factor = static_cast<float>(pbr.metallicFactor);
        out.roughness_factor = static_cast<float>(pbr.roughnessFactor);
        if (in.alphaMode == "OPAQUE")
            out.alpha_mode = AlphaMode::Opaque;
        else if (in.alphaMode == "MASK")
            out.alpha_mode = AlphaMode::Mask;
        else if (in.alphaMode == "BLEND")
            out.alpha_mode = AlphaMode::Blend;
        else
            return fail(what + " has an unknown alphaMode \"" + in.alphaMode + "\"");
        if (!std::isfinite(in.alphaCutoff) || in.alphaCutoff < 0.0)
            return fail(what + " alphaCutoff is not a non-negative number");
        out.alpha_cutoff = static_cast<float>(in.alphaCutoff);
        out.double_sided = in.doubleSided;
        FOCAL_GLTF_TRY(
            textureRef(pbr.baseColorTexture, what + " baseColorTexture", out.base_color_texture));
        FOCAL_GLTF_TRY(
            textureRef(in.emissiveTexture, what + " emissiveTexture", out.emissive_texture));
        // Textures focal does not shade with are still checked so a broken file is reported.
        TextureRef unused;
        FOCAL_GLTF_TRY(
            textureRef(pbr.metallicRoughnessTexture, what + " metallicRoughnessTexture", unused));
        tinygltf::TextureInfo normal_info, occlusion_info;
        normal_info.index = in.normalTexture.index;
        occlusion_info.index = in.occlusionTexture.index;
        FOCAL_GLTF_TRY(textureRef(normal_info, what + " normalTexture", unused));
        FOCAL_GLTF_TRY(textureRef(occlusion_info, what + " occlusionTexture", unused));

        if (in.extensions.count("KHR_materials_unlit"))
            out.unlit = true;
        auto strength = in.extensions.find("KHR_materials_emissive_strength");
        if (strength != in.extensions.end()) {
            const tinygltf::Value& s = strength->second.Get("emissiveStrength");
            if (s.IsNumber()) {
                const double v = s.GetNumberAsDouble();
                if (!std::isfinite(v) || v < 0.0)
                    return fail(what + " emissiveStrength is not a non-negative number");
                out.emissive_factor *= static_cast<float>(v);
            }
        }
        scene_.materials.push_back(std::move(out));
    }
    return {};
}

// Reads accessor `index` as doubles (count * components values; normalized integers already
// mapped to [0,1] or [-1,1]), with every byte range and, for float data, every value checked.
Status Importer::accessorValues(int index, const std::string& what, const AttributeRule* rule,
                                std::vector<double>& out, int& components) {
    if (index < 0 || static_cast<size_t>(index) >= model_.accessors.size())
        return fail(what + " refers to accessor " + std::to_string(index) + ", but there are " +
                    std::to_string(model_.accessors.size()));
    const tinygltf::Accessor& acc = model_.accessors[static_cast<size_t>(index)];
    const std::string name = "accessor " + std::to_string(index);
    const size_t comp_size = componentSize(acc.componentType);
    components = componentCount(acc.type);
    if (comp_size == 0 || components == 0)
        return fail(name + " has an unknown type or componentType");

    // Check the type against what the attribute allows.
    if (rule) {
        const bool type_ok =
            std::find(rule->types.begin(), rule->types.end(), acc.type) != rule->types.end();
        bool comp_ok = false;
        for (const AttributeRule::Component& c : rule->components) {
            if (c.type == acc.componentType &&
                (acc.normalized ? c.normalized_allowed : c.unnormalized_allowed))
                comp_ok = true;
        }
        if (!type_ok || !comp_ok)
            return fail(name + " (" + what + ") has type " + typeName(acc.type) + " of " +
                        (acc.normalized ? "normalized " : "") + componentName(acc.componentType) +
                        ", which " + rule->name + " does not allow");
    }
    // Matrices of 1- and 2-byte components have padded columns (§3.6.2.4); focal reads no
    // matrices, and the padding rule would break the simple stride below.
    if (acc.type == TINYGLTF_TYPE_MAT2 || acc.type == TINYGLTF_TYPE_MAT3 ||
        acc.type == TINYGLTF_TYPE_MAT4)
        return fail(name + " (" + what + ") is a matrix accessor");

    const size_t count = acc.count;
    const size_t ncomp = static_cast<size_t>(components);
    const size_t elem_size = comp_size * ncomp;
    size_t total = 0;
    if (!mulSize(count, ncomp, total) || (acc.bufferView < 0 && count > kMaxZeroAccessorCount))
        return fail(name + " has an implausible count " + std::to_string(count));
    if (acc.bufferView < 0) {
        // Zeros cost nothing in the file: bound them by what the file holds, and the budget.
        zero_elements_ += count;
        zero_value_bytes_ = addBytes(zero_value_bytes_, mulBytes(total, sizeof(double)));
        if (zero_elements_ > zero_element_limit_)
            return fail(name + " (" + what + ") has no bufferView and brings the elements of " +
                        "such accessors read by this file to " + std::to_string(zero_elements_) +
                        ", more than the " + std::to_string(zero_element_limit_) + " a file of " +
                        std::to_string(source_bytes_) + " bytes may declare");
        FOCAL_GLTF_TRY(checkMemory(options_.memory_budget,
                                   path_ + ": reading accessors without a bufferView",
                                   zero_value_bytes_));
    }
    out.clear();

    auto readElements = [&](const unsigned char* base, size_t stride, size_t n, int comp_type,
                            bool normalized, double* dst) {
        for (size_t e = 0; e < n; ++e)
            for (size_t c = 0; c < ncomp; ++c)
                dst[e * ncomp + c] =
                    readComponent(base + e * stride + c * comp_size, comp_type, normalized);
    };

    // Dense data (no bufferView: all zeros, glTF 2.0 §3.6.2.3).
    if (acc.bufferView >= 0 && count > 0) {
        if (static_cast<size_t>(acc.bufferView) >= model_.bufferViews.size())
            return fail(name + " refers to bufferView " + std::to_string(acc.bufferView) +
                        ", but there are " + std::to_string(model_.bufferViews.size()));
        const tinygltf::BufferView& view = model_.bufferViews[static_cast<size_t>(acc.bufferView)];
        size_t stride = view.byteStride == 0 ? elem_size : view.byteStride;
        if (view.byteStride != 0 && (view.byteStride < elem_size || view.byteStride > 252))
            return fail(name + " has an element size of " + std::to_string(elem_size) +
                        " bytes, but bufferView " + std::to_string(acc.bufferView) +
                        " has byteStride " + std::to_string(view.byteStride));
        // offset + stride * (count - 1) + element size, overflow-checked.
        size_t span = 0, end = 0, absolute_end = 0;
        if (!mulSize(stride, count - 1, span) || !addSize(span, elem_size, span) ||
            !addSize(acc.byteOffset, span, end) || !addSize(view.byteOffset, end, absolute_end))
            return fail(name + " reads past the end of bufferView " +
                        std::to_string(acc.bufferView));
        if (view.buffer >= 0 && static_cast<size_t>(view.buffer) < model_.buffers.size() &&
            absolute_end > model_.buffers[static_cast<size_t>(view.buffer)].data.size())
            return fail(name + " reads past the end of buffer " + std::to_string(view.buffer));
        const unsigned char* data = nullptr;
        size_t size = 0;
        FOCAL_GLTF_TRY(bufferViewBytes(acc.bufferView, name, data, size));
        if (end > size)
            return fail(name + " reads past the end of bufferView " +
                        std::to_string(acc.bufferView));
        out.assign(total, 0.0); // bounded by the buffer's size: count * elem_size <= end
        readElements(data + acc.byteOffset, stride, count, acc.componentType, acc.normalized,
                     out.data());
    }

    if (out.size() != total)
        out.assign(total, 0.0);

    // Sparse substitution (§3.6.2.3): `count` strictly increasing element indices, then values.
    if (acc.sparse.isSparse) {
        const std::string sparse_name = name + " sparse";
        if (acc.sparse.count < 0 || static_cast<size_t>(acc.sparse.count) > count)
            return fail(sparse_name + " count " + std::to_string(acc.sparse.count) +
                        " is out of range");
        const size_t n = static_cast<size_t>(acc.sparse.count);
        const int idx_type = acc.sparse.indices.componentType;
        const size_t idx_size = componentSize(idx_type);
        if (idx_type != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE &&
            idx_type != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
            idx_type != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT)
            return fail(sparse_name + " indices have componentType " + componentName(idx_type));
        if (acc.sparse.indices.byteOffset < 0 || acc.sparse.values.byteOffset < 0)
            return fail(sparse_name + " has a negative byteOffset");
        const unsigned char* idx_data = nullptr;
        const unsigned char* val_data = nullptr;
        size_t idx_bytes = 0, val_bytes = 0;
        FOCAL_GLTF_TRY(bufferViewBytes(acc.sparse.indices.bufferView, sparse_name + " indices",
                                       idx_data, idx_bytes));
        FOCAL_GLTF_TRY(bufferViewBytes(acc.sparse.values.bufferView, sparse_name + " values",
                                       val_data, val_bytes));
        const size_t idx_offset = static_cast<size_t>(acc.sparse.indices.byteOffset);
        const size_t val_offset = static_cast<size_t>(acc.sparse.values.byteOffset);
        size_t idx_end = 0, val_end = 0;
        if (!mulSize(n, idx_size, idx_end) || !addSize(idx_end, idx_offset, idx_end) ||
            idx_end > idx_bytes)
            return fail(sparse_name + " indices read past the end of bufferView " +
                        std::to_string(acc.sparse.indices.bufferView));
        if (!mulSize(n, elem_size, val_end) || !addSize(val_end, val_offset, val_end) ||
            val_end > val_bytes)
            return fail(sparse_name + " values read past the end of bufferView " +
                        std::to_string(acc.sparse.values.bufferView));
        std::vector<double> values(n * ncomp);
        readElements(val_data + val_offset, elem_size, n, acc.componentType, acc.normalized,
                     values.data());
        double previous = -1.0;
        for (size_t k = 0; k < n; ++k) {
            const double target =
                readComponent(idx_data + idx_offset + k * idx_size, idx_type, false);
            if (target <= previous || target >= static_cast<double>(count))
                return fail(sparse_name + " index " + std::to_string(k) +
                            " is out of range or not increasing");
            previous = target;
            const size_t t = static_cast<size_t>(target);
            std::copy_n(values.begin() + static_cast<std::ptrdiff_t>(k * ncomp), ncomp,
                        out.begin() + static_cast<std::ptrdiff_t>(t * ncomp));
        }
    }

    if (acc.componentType == TINYGLTF_COMPONENT_TYPE_FLOAT) {
        for (size_t k = 0; k < out.size(); ++k) {
            if (!std::isfinite(out[k]))
                return fail(name + " (" + what +
                            ") has a non-finite value (NaN or Inf) in element " +
                            std::to_string(k / ncomp));
        }
    }
    return {};
}

const AttributeRule& positionRule(bool quantized) {
    using C = AttributeRule::Component;
    static const AttributeRule plain{
        "POSITION", {TINYGLTF_TYPE_VEC3}, {C{TINYGLTF_COMPONENT_TYPE_FLOAT, false, true}}};
    static const AttributeRule quant{"POSITION",
                                     {TINYGLTF_TYPE_VEC3},
                                     {C{TINYGLTF_COMPONENT_TYPE_FLOAT, false, true},
                                      C{TINYGLTF_COMPONENT_TYPE_BYTE, true, true},
                                      C{TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE, true, true},
                                      C{TINYGLTF_COMPONENT_TYPE_SHORT, true, true},
                                      C{TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT, true, true}}};
    return quantized ? quant : plain;
}

const AttributeRule& normalRule(bool quantized) {
    using C = AttributeRule::Component;
    static const AttributeRule plain{
        "NORMAL", {TINYGLTF_TYPE_VEC3}, {C{TINYGLTF_COMPONENT_TYPE_FLOAT, false, true}}};
    static const AttributeRule quant{"NORMAL",
                                     {TINYGLTF_TYPE_VEC3},
                                     {C{TINYGLTF_COMPONENT_TYPE_FLOAT, false, true},
                                      C{TINYGLTF_COMPONENT_TYPE_BYTE, true, false},
                                      C{TINYGLTF_COMPONENT_TYPE_SHORT, true, false}}};
    return quantized ? quant : plain;
}

const AttributeRule& texcoordRule(bool quantized) {
    using C = AttributeRule::Component;
    static const AttributeRule plain{"TEXCOORD_0",
                                     {TINYGLTF_TYPE_VEC2},
                                     {C{TINYGLTF_COMPONENT_TYPE_FLOAT, false, true},
                                      C{TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE, true, false},
                                      C{TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT, true, false}}};
    static const AttributeRule quant{"TEXCOORD_0",
                                     {TINYGLTF_TYPE_VEC2},
                                     {C{TINYGLTF_COMPONENT_TYPE_FLOAT, false, true},
                                      C{TINYGLTF_COMPONENT_TYPE_BYTE, true, true},
                                      C{TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE, true, true},
                                      C{TINYGLTF_COMPONENT_TYPE_SHORT, true, true},
                                      C{TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT, true, true}}};
    return quantized ? quant : plain;
}

const AttributeRule& colorRule() {
    using C = AttributeRule::Component;
    static const AttributeRule rule{"COLOR_0",
                                    {TINYGLTF_TYPE_VEC3, TINYGLTF_TYPE_VEC4},
                                    {C{TINYGLTF_COMPONENT_TYPE_FLOAT, false, true},
                                     C{TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE, true, false},
                                     C{TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT, true, false}}};
    return rule;
}

const AttributeRule& indexRule() {
    using C = AttributeRule::Component;
    static const AttributeRule rule{"indices",
                                    {TINYGLTF_TYPE_SCALAR},
                                    {C{TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE, false, true},
                                     C{TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT, false, true},
                                     C{TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT, false, true}}};
    return rule;
}

Status Importer::convertPrimitive(size_t mesh_index, size_t prim_index,
                                  const tinygltf::Primitive& in, Primitive& out, bool& keep) {
    const std::string what =
        "mesh " + std::to_string(mesh_index) + " primitive " + std::to_string(prim_index);
    keep = false;
    const int mode = in.mode < 0 ? TINYGLTF_MODE_TRIANGLES : in.mode;
    if (mode > TINYGLTF_MODE_TRIANGLE_FAN)
        return fail(what + " has an unknown mode " + std::to_string(mode));

    // Every referenced accessor must exist, even those focal does not read.
    for (const auto& [attribute, accessor] : in.attributes) {
        if (accessor < 0 || static_cast<size_t>(accessor) >= model_.accessors.size())
            return fail(what + " attribute " + attribute + " refers to accessor " +
                        std::to_string(accessor) + ", but there are " +
                        std::to_string(model_.accessors.size()));
    }
    if (in.material >= 0 && static_cast<size_t>(in.material) >= model_.materials.size())
        return fail(what + " refers to material " + std::to_string(in.material) +
                    ", but there are " + std::to_string(model_.materials.size()));
    if (in.material < -1)
        return fail(what + " has a negative material index");

    if (mode < TINYGLTF_MODE_TRIANGLES) {
        static const char* kModeNames[] = {"points", "lines", "line loop", "line strip"};
        warn(what + " draws " + kModeNames[mode] + "; skipped (focal draws triangles only)");
        return {};
    }
    auto position = in.attributes.find("POSITION");
    if (position == in.attributes.end()) {
        warn(what + " has no POSITION attribute; skipped");
        return {};
    }

    // Vertex attributes.
    std::vector<double> values;
    int comps = 0;
    FOCAL_GLTF_TRY(accessorValues(position->second, what + " POSITION",
                                  &positionRule(quantization_), values, comps));
    const size_t vertex_count = values.size() / 3;
    out.positions.resize(vertex_count);
    for (size_t v = 0; v < vertex_count; ++v)
        out.positions[v] = glm::vec3(values[3 * v], values[3 * v + 1], values[3 * v + 2]);

    auto sameCount = [&](const char* attribute, size_t n) -> Status {
        if (n != vertex_count)
            return fail(what + " " + attribute + " has " + std::to_string(n) +
                        " elements, but POSITION has " + std::to_string(vertex_count));
        return {};
    };
    if (auto it = in.attributes.find("NORMAL"); it != in.attributes.end()) {
        FOCAL_GLTF_TRY(accessorValues(it->second, what + " NORMAL", &normalRule(quantization_),
                                      values, comps));
        FOCAL_GLTF_TRY(sameCount("NORMAL", values.size() / 3));
        out.normals.resize(vertex_count);
        for (size_t v = 0; v < vertex_count; ++v)
            out.normals[v] = glm::vec3(values[3 * v], values[3 * v + 1], values[3 * v + 2]);
    }
    if (auto it = in.attributes.find("TEXCOORD_0"); it != in.attributes.end()) {
        FOCAL_GLTF_TRY(accessorValues(it->second, what + " TEXCOORD_0",
                                      &texcoordRule(quantization_), values, comps));
        FOCAL_GLTF_TRY(sameCount("TEXCOORD_0", values.size() / 2));
        out.texcoords0.resize(vertex_count);
        for (size_t v = 0; v < vertex_count; ++v)
            out.texcoords0[v] = glm::vec2(values[2 * v], values[2 * v + 1]);
    }
    if (auto it = in.attributes.find("COLOR_0"); it != in.attributes.end()) {
        FOCAL_GLTF_TRY(accessorValues(it->second, what + " COLOR_0", &colorRule(), values, comps));
        const size_t n = static_cast<size_t>(comps);
        FOCAL_GLTF_TRY(sameCount("COLOR_0", values.size() / n));
        out.colors.resize(vertex_count);
        for (size_t v = 0; v < vertex_count; ++v)
            out.colors[v] = glm::vec4(values[n * v], values[n * v + 1], values[n * v + 2],
                                      n == 4 ? values[n * v + 3] : 1.0);
    }

    // Indices (implicit 0..n-1 when absent), each checked against the vertex count.
    std::vector<uint32_t> order;
    if (in.indices >= 0) {
        FOCAL_GLTF_TRY(accessorValues(in.indices, what + " indices", &indexRule(), values, comps));
        order.resize(values.size());
        for (size_t k = 0; k < values.size(); ++k) {
            if (values[k] >= static_cast<double>(vertex_count))
                return fail(what + " index " + std::to_string(static_cast<uint64_t>(values[k])) +
                            " (element " + std::to_string(k) + " of accessor " +
                            std::to_string(in.indices) + ") is out of range: there are " +
                            std::to_string(vertex_count) + " vertices");
            order[k] = static_cast<uint32_t>(values[k]);
        }
    } else {
        if (vertex_count > std::numeric_limits<uint32_t>::max())
            return fail(what + " has too many vertices");
        order.resize(vertex_count);
        for (size_t k = 0; k < vertex_count; ++k)
            order[k] = static_cast<uint32_t>(k);
    }

    // Triangle lists; strips and fans converted (glTF 2.0 §3.7.2.1, "Topology types").
    const size_t n = order.size();
    if (mode == TINYGLTF_MODE_TRIANGLES) {
        if (n % 3 != 0)
            return fail(what + " has " + std::to_string(n) +
                        " indices, which is not a multiple of 3");
        out.indices = std::move(order);
    } else if (n >= 3) {
        out.indices.reserve((n - 2) * 3);
        for (size_t i = 0; i + 2 < n; ++i) {
            if (mode == TINYGLTF_MODE_TRIANGLE_STRIP) {
                // p_i, p_{i+(1+i%2)}, p_{i+(2-i%2)}: keeps every triangle's winding.
                out.indices.push_back(order[i]);
                out.indices.push_back(order[i + 1 + i % 2]);
                out.indices.push_back(order[i + 2 - i % 2]);
            } else {
                // p_{i+1}, p_{i+2}, p_0.
                out.indices.push_back(order[i + 1]);
                out.indices.push_back(order[i + 2]);
                out.indices.push_back(order[0]);
            }
        }
    }
    out.material = in.material;
    keep = true;
    return {};
}

Status Importer::convertMeshes() {
    bool morph_warned = false;
    for (size_t m = 0; m < model_.meshes.size(); ++m) {
        const tinygltf::Mesh& in = model_.meshes[m];
        Mesh out;
        out.name = in.name;
        for (size_t p = 0; p < in.primitives.size(); ++p) {
            Primitive prim;
            bool keep = false;
            FOCAL_GLTF_TRY(convertPrimitive(m, p, in.primitives[p], prim, keep));
            if (!in.primitives[p].targets.empty() && !morph_warned) {
                warn("morph targets are not supported; meshes are drawn in their base shape");
                morph_warned = true;
            }
            if (keep)
                out.primitives.push_back(std::move(prim));
        }
        scene_.meshes.push_back(std::move(out));
    }
    return {};
}

// Every child index in range, no node with two parents, no cycles.
Status Importer::checkNodeGraph() {
    const size_t count = model_.nodes.size();
    std::vector<int> parent(count, -1);
    for (size_t i = 0; i < count; ++i) {
        for (int child : model_.nodes[i].children) {
            if (child < 0 || static_cast<size_t>(child) >= count)
                return fail("node " + std::to_string(i) + " has child " + std::to_string(child) +
                            ", but there are " + std::to_string(count) + " nodes");
            const size_t c = static_cast<size_t>(child);
            if (c == i)
                return fail("node " + std::to_string(i) + " is its own child (cycle)");
            if (parent[c] >= 0)
                return fail("node " + std::to_string(c) + " has two parents (nodes " +
                            std::to_string(parent[c]) + " and " + std::to_string(i) + ")");
            parent[c] = static_cast<int>(i);
        }
    }
    // With one parent each, a cycle is a parent chain that never reaches a root.
    std::vector<uint8_t> state(count, 0); // 0 unvisited, 1 on the current walk, 2 reaches a root
    for (size_t i = 0; i < count; ++i) {
        std::vector<size_t> walk;
        size_t n = i;
        while (state[n] == 0) {
            state[n] = 1;
            walk.push_back(n);
            if (parent[n] < 0)
                break;
            n = static_cast<size_t>(parent[n]);
        }
        if (state[n] == 1 && parent[n] >= 0)
            return fail("node " + std::to_string(n) + " is its own ancestor (node cycle)");
        for (size_t w : walk)
            state[w] = 2;
    }
    return {};
}

// Node transform: `matrix` (column-major) or T * R * S (glTF 2.0 §3.5.3).
Status Importer::localMatrix(size_t node_index, glm::mat4& out) {
    const tinygltf::Node& node = model_.nodes[node_index];
    const std::string what = "node " + std::to_string(node_index);
    auto finite = [](const std::vector<double>& v) {
        return std::all_of(v.begin(), v.end(), [](double x) { return std::isfinite(x); });
    };
    if (!finite(node.matrix) || !finite(node.translation) || !finite(node.rotation) ||
        !finite(node.scale))
        return fail(what + " has a non-finite transform");
    out = glm::mat4(1.0f);
    if (!node.matrix.empty()) {
        if (node.matrix.size() != 16)
            return fail(what + " matrix does not have 16 entries");
        for (int c = 0; c < 4; ++c)
            for (int r = 0; r < 4; ++r)
                out[c][r] = static_cast<float>(node.matrix[static_cast<size_t>(c * 4 + r)]);
        return {};
    }
    if (!node.translation.empty() && node.translation.size() != 3)
        return fail(what + " translation does not have 3 entries");
    if (!node.rotation.empty() && node.rotation.size() != 4)
        return fail(what + " rotation does not have 4 entries");
    if (!node.scale.empty() && node.scale.size() != 3)
        return fail(what + " scale does not have 3 entries");
    glm::mat4 t(1.0f), r(1.0f), s(1.0f);
    if (!node.translation.empty())
        t[3] = glm::vec4(static_cast<float>(node.translation[0]),
                         static_cast<float>(node.translation[1]),
                         static_cast<float>(node.translation[2]), 1.0f);
    if (!node.rotation.empty()) {
        // Unit quaternion (x, y, z, w) to a rotation matrix.
        double x = node.rotation[0], y = node.rotation[1], z = node.rotation[2],
               w = node.rotation[3];
        const double len = std::sqrt(x * x + y * y + z * z + w * w);
        if (!(len > 1e-12))
            return fail(what + " rotation is a zero quaternion");
        x /= len;
        y /= len;
        z /= len;
        w /= len;
        r[0] = glm::vec4(static_cast<float>(1 - 2 * (y * y + z * z)),
                         static_cast<float>(2 * (x * y + z * w)),
                         static_cast<float>(2 * (x * z - y * w)), 0.0f);
        r[1] = glm::vec4(static_cast<float>(2 * (x * y - z * w)),
                         static_cast<float>(1 - 2 * (x * x + z * z)),
                         static_cast<float>(2 * (y * z + x * w)), 0.0f);
        r[2] = glm::vec4(static_cast<float>(2 * (x * z + y * w)),
                         static_cast<float>(2 * (y * z - x * w)),
                         static_cast<float>(1 - 2 * (x * x + y * y)), 0.0f);
    }
    if (!node.scale.empty()) {
        s[0][0] = static_cast<float>(node.scale[0]);
        s[1][1] = static_cast<float>(node.scale[1]);
        s[2][2] = static_cast<float>(node.scale[2]);
    }
    out = t * r * s;
    return {};
}

Status Importer::placeCamera(size_t node_index, const glm::mat4& world) {
    const int index = model_.nodes[node_index].camera;
    if (index < 0 || static_cast<size_t>(index) >= model_.cameras.size())
        return fail("node " + std::to_string(node_index) + " refers to camera " +
                    std::to_string(index) + ", but there are " +
                    std::to_string(model_.cameras.size()));
    const tinygltf::Camera& in = model_.cameras[static_cast<size_t>(index)];
    const std::string what = "camera " + std::to_string(index);
    if (in.type == "orthographic") {
        warn(what + " is orthographic; skipped (focal renders perspective cameras)");
        return {};
    }
    if (in.type != "perspective")
        return fail(what + " has an unknown type \"" + in.type + "\"");
    const tinygltf::PerspectiveCamera& p = in.perspective;
    if (!std::isfinite(p.yfov) || p.yfov <= 0.0 || p.yfov >= 3.14159265358979)
        return fail(what + " yfov is not in (0, pi)");
    if (!std::isfinite(p.znear) || p.znear <= 0.0)
        return fail(what + " znear is not positive");
    if (!std::isfinite(p.zfar) || (p.zfar != 0.0 && p.zfar <= p.znear))
        return fail(what + " zfar is not greater than znear");
    if (!std::isfinite(p.aspectRatio) || p.aspectRatio < 0.0)
        return fail(what + " aspectRatio is negative");
    Camera out;
    out.name = in.name.empty() ? model_.nodes[node_index].name : in.name;
    out.world = world;
    out.yfov = static_cast<float>(p.yfov);
    out.aspect_ratio = static_cast<float>(p.aspectRatio);
    out.znear = static_cast<float>(p.znear);
    out.zfar = static_cast<float>(p.zfar);
    scene_.cameras.push_back(std::move(out));
    return {};
}

Status Importer::placeLight(size_t node_index, const tinygltf::Value& ext, const glm::mat4& world) {
    const std::string node_name = "node " + std::to_string(node_index);
    const tinygltf::Value& light_value = ext.Get("light");
    if (!light_value.IsInt())
        return fail(node_name + " KHR_lights_punctual has no integer light index");
    const int index = light_value.GetNumberAsInt();
    if (index < 0 || static_cast<size_t>(index) >= model_.lights.size())
        return fail(node_name + " refers to light " + std::to_string(index) + ", but there are " +
                    std::to_string(model_.lights.size()));
    const tinygltf::Light& in = model_.lights[static_cast<size_t>(index)];
    const std::string what = "light " + std::to_string(index);
    Light out;
    out.name = in.name;
    if (in.type == "directional")
        out.type = Light::Type::Directional;
    else if (in.type == "point")
        out.type = Light::Type::Point;
    else if (in.type == "spot")
        out.type = Light::Type::Spot;
    else
        return fail(what + " has an unknown type \"" + in.type + "\"");
    if (!in.color.empty()) {
        if (in.color.size() != 3)
            return fail(what + " color does not have 3 entries");
        for (int k = 0; k < 3; ++k) {
            if (!std::isfinite(in.color[static_cast<size_t>(k)]))
                return fail(what + " color is not finite");
            out.color[k] = static_cast<float>(in.color[static_cast<size_t>(k)]);
        }
    }
    if (!std::isfinite(in.intensity) || in.intensity < 0.0)
        return fail(what + " intensity is not a non-negative number");
    if (!std::isfinite(in.range) || in.range < 0.0)
        return fail(what + " range is negative");
    out.intensity = static_cast<float>(in.intensity);
    out.range = static_cast<float>(in.range);
    if (out.type == Light::Type::Spot) {
        const double inner = in.spot.innerConeAngle, outer = in.spot.outerConeAngle;
        if (!std::isfinite(inner) || !std::isfinite(outer) || inner < 0.0 || outer <= inner ||
            outer > 1.5707963267949)
            return fail(what + " spot cone angles are not 0 <= inner < outer <= pi/2");
        out.inner_cone_angle = static_cast<float>(inner);
        out.outer_cone_angle = static_cast<float>(outer);
    }
    // The light sits at the node's origin and shines down the node's -Z (extension README).
    out.position = glm::vec3(world * glm::vec4(0.0f, 0.0f, 0.0f, 1.0f));
    const glm::vec3 dir = glm::vec3(world * glm::vec4(0.0f, 0.0f, -1.0f, 0.0f));
    const float len = glm::length(dir);
    if (!(len > 0.0f) || !std::isfinite(len))
        return fail(node_name + " places light " + std::to_string(index) +
                    " with a degenerate transform");
    out.direction = dir / len;
    scene_.lights.push_back(std::move(out));
    return {};
}

Status Importer::convertNodes() {
    FOCAL_GLTF_TRY(checkNodeGraph());

    // Roots: the default scene, else scene 0, else every node without a parent.
    std::vector<int> roots;
    if (model_.defaultScene >= 0) {
        if (static_cast<size_t>(model_.defaultScene) >= model_.scenes.size())
            return fail("default scene " + std::to_string(model_.defaultScene) +
                        " is out of range: there are " + std::to_string(model_.scenes.size()) +
                        " scenes");
        roots = model_.scenes[static_cast<size_t>(model_.defaultScene)].nodes;
    } else if (!model_.scenes.empty()) {
        roots = model_.scenes[0].nodes;
    } else {
        std::vector<bool> is_child(model_.nodes.size(), false);
        for (const tinygltf::Node& node : model_.nodes)
            for (int child : node.children)
                is_child[static_cast<size_t>(child)] = true;
        for (size_t i = 0; i < model_.nodes.size(); ++i)
            if (!is_child[i])
                roots.push_back(static_cast<int>(i));
    }
    std::vector<bool> is_child(model_.nodes.size(), false);
    for (const tinygltf::Node& node : model_.nodes)
        for (int child : node.children)
            is_child[static_cast<size_t>(child)] = true;
    std::set<int> seen_roots;
    for (int root : roots) {
        if (root < 0 || static_cast<size_t>(root) >= model_.nodes.size())
            return fail("scene refers to node " + std::to_string(root) + ", but there are " +
                        std::to_string(model_.nodes.size()) + " nodes");
        if (is_child[static_cast<size_t>(root)])
            return fail("scene lists node " + std::to_string(root) +
                        ", which is not a root node (it has a parent)");
        if (!seen_roots.insert(root).second)
            return fail("scene lists node " + std::to_string(root) + " twice");
    }

    // Walk each tree with an explicit stack (deep hierarchies must not overflow the call stack);
    // world = parent world * local, in depth-first pre-order so instance order follows the file.
    bool skin_warned = false;
    for (int root : roots) {
        std::vector<std::pair<size_t, glm::mat4>> stack;
        stack.emplace_back(static_cast<size_t>(root), glm::mat4(1.0f));
        while (!stack.empty()) {
            auto [index, parent_world] = stack.back();
            stack.pop_back();
            const tinygltf::Node& node = model_.nodes[index];
            glm::mat4 local;
            FOCAL_GLTF_TRY(localMatrix(index, local));
            const glm::mat4 world = parent_world * local;
            if (node.mesh >= 0 || node.mesh < -1) {
                if (node.mesh < 0 || static_cast<size_t>(node.mesh) >= model_.meshes.size())
                    return fail("node " + std::to_string(index) + " refers to mesh " +
                                std::to_string(node.mesh) + ", but there are " +
                                std::to_string(model_.meshes.size()));
                scene_.instances.push_back(Instance{static_cast<uint32_t>(node.mesh), world});
            }
            if (node.skin >= 0 && !skin_warned) {
                warn("skins are not supported; skinned meshes are drawn in their bind pose");
                skin_warned = true;
            }
            if (node.camera != -1)
                FOCAL_GLTF_TRY(placeCamera(index, world));
            auto light = node.extensions.find("KHR_lights_punctual");
            if (light != node.extensions.end())
                FOCAL_GLTF_TRY(placeLight(index, light->second, world));
            for (auto it = node.children.rbegin(); it != node.children.rend(); ++it)
                stack.emplace_back(static_cast<size_t>(*it), world);
        }
    }
    return {};
}

Status Importer::run(const CapturedImages& captured) {
    FOCAL_GLTF_TRY(checkExtensions());
    FOCAL_GLTF_TRY(convertSamplers());
    FOCAL_GLTF_TRY(convertImages(captured));
    const auto t0 = std::chrono::steady_clock::now();
    FOCAL_GLTF_TRY(convertMaterials());
    FOCAL_GLTF_TRY(convertMeshes());
    FOCAL_GLTF_TRY(convertNodes());
    stats_.ms_scene = msSince(t0);
    if (!model_.animations.empty())
        warn("animations are not supported; the scene is drawn at rest");

    uint64_t triangles = 0;
    for (const Instance& instance : scene_.instances)
        for (const Primitive& prim : scene_.meshes[instance.mesh].primitives)
            triangles += prim.indices.size() / 3;
    if (triangles == 0)
        return fail("no triangles to render");
    return {};
}

// Rewrites tinygltf's own error text into one line (it appends lines with '\n').
std::string tinygltfError(const std::string& err) {
    std::string line = firstLine(err);
    if (line.empty())
        return "cannot be parsed as glTF";
    if (startsWith(line, "[json.exception.")) {
        const size_t close = line.find("] ");
        return "invalid JSON: " + (close == std::string::npos ? line : line.substr(close + 2));
    }
    if (startsWith(line, "File not found : "))
        return "buffer file not found: " + line.substr(std::strlen("File not found : "));
    if (startsWith(line, "File read error : ")) {
        // "File read error : PATH : WHY" (from readWholeFile)
        const std::string rest = line.substr(std::strlen("File read error : "));
        const size_t sep = rest.rfind(" : ");
        return sep == std::string::npos
                   ? "cannot read a buffer file: " + rest
                   : "buffer file " + rest.substr(0, sep) + " " + rest.substr(sep + 3);
    }
    return line;
}

// The deepest nesting of arrays and objects in JSON text (strings skipped), stopping as soon as
// it exceeds `limit`; `at` is the byte offset where it did.
size_t jsonDepth(const unsigned char* text, size_t size, size_t limit, size_t& at) {
    size_t depth = 0, deepest = 0;
    bool in_string = false;
    for (size_t i = 0; i < size; ++i) {
        const unsigned char c = text[i];
        if (in_string) {
            if (c == '\\')
                ++i; // skip the escaped character
            else if (c == '"')
                in_string = false;
        } else if (c == '"') {
            in_string = true;
        } else if (c == '[' || c == '{') {
            deepest = std::max(deepest, ++depth);
            if (deepest > limit) {
                at = i;
                return deepest;
            }
        } else if ((c == ']' || c == '}') && depth > 0) {
            --depth;
        }
    }
    return deepest;
}

// The JSON text of a .gltf (all of it) or a .glb (its first chunk, when the header is sound;
// tinygltf reports broken headers).
std::pair<const unsigned char*, size_t> jsonText(const unsigned char* bytes, size_t size,
                                                 bool glb) {
    if (!glb)
        return {bytes, size};
    if (size < 20)
        return {bytes, 0};
    uint32_t chunk_length = 0;
    std::memcpy(&chunk_length, bytes + 12, 4); // little-endian, as x86-64 and ARM64 are
    return {bytes + 20, std::min<size_t>(chunk_length, size - 20)};
}

// Reads a file tinygltf asks for (buffers and images given by uri): only regular files, and
// none larger than the memory budget. tinygltf's own reader takes a directory's size to be
// huge and fails with std::bad_alloc ("out of memory" for a uri of "/").
bool readWholeFile(std::vector<unsigned char>* out, std::string* err, const std::string& path,
                   void* user_data) {
    const MemoryBudget& budget = *static_cast<const MemoryBudget*>(user_data);
    std::error_code ec;
    const std::filesystem::file_status st = std::filesystem::status(path, ec);
    if (ec || !std::filesystem::exists(st)) {
        *err = "not found";
        return false;
    }
    if (std::filesystem::is_directory(st)) {
        *err = "is a directory, not a file";
        return false;
    }
    if (!std::filesystem::is_regular_file(st)) {
        *err = "is not a regular file";
        return false;
    }
    const uintmax_t size = std::filesystem::file_size(path, ec);
    if (ec) {
        *err = "cannot read its size";
        return false;
    }
    if (Status s = checkMemory(budget, "reading it", size); !s.ok()) {
        *err = s.message();
        return false;
    }
    std::ifstream file(path, std::ios::binary);
    out->resize(size);
    if (!file || !file.read(reinterpret_cast<char*>(out->data()), std::streamsize(size))) {
        *err = "read error";
        return false;
    }
    return true;
}

Result<Scene> importBytes(const unsigned char* bytes, size_t size, const std::string& path,
                          const std::string& base_dir, const ImportOptions& options,
                          ImportStats& stats, std::chrono::steady_clock::time_point t0) {
    if (size == 0)
        return Status::error(path + ": file is empty");
    if (size > std::numeric_limits<unsigned int>::max())
        return Status::error(path + ": file is larger than 4 GiB");
    const bool glb = size >= 4 && std::memcmp(bytes, "glTF", 4) == 0;
    // Bound the nesting before the recursive JSON parser sees it.
    const auto [json, json_size] = jsonText(bytes, size, glb);
    size_t deep_at = 0;
    if (jsonDepth(json, json_size, kMaxJsonDepth, deep_at) > kMaxJsonDepth)
        return Status::error(path + ": JSON nests deeper than " + std::to_string(kMaxJsonDepth) +
                             " levels (at byte " + std::to_string(deep_at + size_t(json - bytes)) +
                             "), the most focal accepts");

    tinygltf::TinyGLTF loader;
    CapturedImages captured;
    loader.SetImageLoader(&captureImage, &captured);
    MemoryBudget budget = options.memory_budget;
    loader.SetFsCallbacks({&tinygltf::FileExists, &tinygltf::ExpandFilePath, &readWholeFile,
                           &tinygltf::WriteWholeFile, &budget});
    tinygltf::Model model;
    std::string err, warn_text;
    const unsigned int length = static_cast<unsigned int>(size);
    const bool loaded =
        glb ? loader.LoadBinaryFromMemory(&model, &err, &warn_text, bytes, length, base_dir)
            : loader.LoadASCIIFromString(&model, &err, &warn_text,
                                         reinterpret_cast<const char*>(bytes), length, base_dir);
    if (!loaded) {
        std::string message = tinygltfError(err);
        if (glb && !startsWith(message, "invalid JSON")) {
            while (!message.empty() && message.back() == '.')
                message.pop_back();
            message = "invalid GLB file: " + message;
        }
        return Status::error(path + ": " + message);
    }

    Scene scene;
    scene.source = path;
    // tinygltf's warnings, minus the image ones: images are reported precisely by convertImages.
    for (std::string& line : lines(warn_text)) {
        if (startsWith(line, "File not found") || line.find("for image[") != std::string::npos)
            continue;
        scene.warnings.push_back("tinygltf: " + line);
    }
    stats.ms_parse = msSince(t0);
    uint64_t source_bytes = size;
    for (const tinygltf::Buffer& b : model.buffers)
        source_bytes = addBytes(source_bytes, b.data.size());
    Importer importer(path, model, scene, options, stats, source_bytes);
    Status status = importer.run(captured);
    if (!status.ok())
        return status;
    return scene;
}

Result<Scene> importImpl(const std::string& path, const ImportOptions& options,
                         ImportStats& stats) {
    const auto t0 = std::chrono::steady_clock::now();
    // Read the whole file ourselves: precise "not found" messages, and GLB is recognised by its
    // magic rather than its name.
    std::error_code ec;
    const std::filesystem::file_status st = std::filesystem::status(path, ec);
    if (ec || !std::filesystem::exists(st))
        return Status::error(path + ": file not found");
    if (std::filesystem::is_directory(st))
        return Status::error(path + ": is a directory, not a glTF file");
    // /dev/zero or a pipe would be read forever.
    if (!std::filesystem::is_regular_file(st))
        return Status::error(path + ": is not a regular file");
    const uintmax_t file_size = std::filesystem::file_size(path, ec);
    if (!ec)
        FOCAL_GLTF_TRY(
            checkMemory(options.memory_budget, path + ": reading the file", uint64_t(file_size)));
    std::ifstream file(path, std::ios::binary);
    if (!file)
        return Status::error(path + ": cannot be opened");
    std::vector<unsigned char> bytes((std::istreambuf_iterator<char>(file)),
                                     std::istreambuf_iterator<char>());
    if (file.bad())
        return Status::error(path + ": read error");

    std::string base_dir = std::filesystem::path(path).parent_path().string();
    if (base_dir.empty())
        base_dir = ".";
    return importBytes(bytes.data(), bytes.size(), path, base_dir, options, stats, t0);
}

// One line, no control characters, bounded length (tinygltf may quote a whole data URI).
Status oneLine(const Status& status) {
    std::string message = status.message();
    for (char& ch : message) {
        if (static_cast<unsigned char>(ch) < 0x20 || ch == 0x7f)
            ch = ' ';
    }
    constexpr size_t kMaxLength = 400;
    if (message.size() > kMaxLength)
        message = message.substr(0, kMaxLength) + "...";
    return Status::error(std::move(message));
}

// Runs an import with its messages made one line, its total time measured, and anything
// tinygltf throws turned into an error naming the file.
template <class Import>
Result<Scene> guardedImport(const std::string& path, ImportStats* stats, Import&& import) {
    const auto t0 = std::chrono::steady_clock::now();
    ImportStats local;
    ImportStats& out = stats ? *stats : local;
    out = ImportStats{};
    try {
        Result<Scene> scene = import(out, t0);
        out.ms_total = msSince(t0);
        if (!scene.ok())
            return oneLine(scene.status());
        return scene;
    } catch (const std::bad_alloc&) {
        return Status::error(path + ": out of memory");
    } catch (const std::exception& e) {
        std::string what = firstLine(e.what());
        if (startsWith(what, "[json.exception."))
            return oneLine(Status::error(path + ": " + tinygltfError(what)));
        return oneLine(Status::error(path + ": " + (what.empty() ? "import failed" : what)));
    } catch (...) {
        return Status::error(path + ": import failed");
    }
}

} // namespace

Result<Scene> importGltf(const std::string& path, const ImportOptions& options,
                         ImportStats* stats) {
    return guardedImport(path, stats,
                         [&](ImportStats& out, auto) { return importImpl(path, options, out); });
}

Result<Scene> importGltfFromMemory(const unsigned char* data, size_t size, const std::string& name,
                                   const std::string& base_dir, const ImportOptions& options,
                                   ImportStats* stats) {
    return guardedImport(name, stats, [&](ImportStats& out, auto t0) {
        return importBytes(data, size, name, base_dir, options, out, t0);
    });
}

} // namespace raster
