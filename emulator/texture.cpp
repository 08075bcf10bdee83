#include "emulator/texture.h"

#include <OpenImageIO/imagecache.h>
#include <OpenImageIO/texture.h>

#include <algorithm>
#include <cmath>
#include <mutex>
#include <vector>

#include "core/file_input.h"
#include "core/error.h"
#include "emulator/validation.h"

namespace refray::dxr {

std::string_view toString(SamplerFilter filter) {
    switch (filter) {
        case FILTER_MIN_MAG_MIP_POINT: return "MIN_MAG_MIP_POINT";
        case FILTER_MIN_MAG_POINT_MIP_LINEAR: return "MIN_MAG_POINT_MIP_LINEAR";
        case FILTER_MIN_POINT_MAG_LINEAR_MIP_POINT: return "MIN_POINT_MAG_LINEAR_MIP_POINT";
        case FILTER_MIN_POINT_MAG_MIP_LINEAR: return "MIN_POINT_MAG_MIP_LINEAR";
        case FILTER_MIN_LINEAR_MAG_MIP_POINT: return "MIN_LINEAR_MAG_MIP_POINT";
        case FILTER_MIN_LINEAR_MAG_POINT_MIP_LINEAR: return "MIN_LINEAR_MAG_POINT_MIP_LINEAR";
        case FILTER_MIN_MAG_LINEAR_MIP_POINT: return "MIN_MAG_LINEAR_MIP_POINT";
        case FILTER_MIN_MAG_MIP_LINEAR: return "MIN_MAG_MIP_LINEAR";
        case FILTER_ANISOTROPIC: return "ANISOTROPIC";
    }
    return "?";
}

std::string_view toString(TextureAddressMode mode) {
    switch (mode) {
        case TEXTURE_ADDRESS_MODE_WRAP: return "WRAP";
        case TEXTURE_ADDRESS_MODE_MIRROR: return "MIRROR";
        case TEXTURE_ADDRESS_MODE_CLAMP: return "CLAMP";
        case TEXTURE_ADDRESS_MODE_BORDER: return "BORDER";
        case TEXTURE_ADDRESS_MODE_MIRROR_ONCE: return "MIRROR_ONCE";
    }
    return "?";
}

vec4 toColor(StaticBorderColor color) {
    switch (color) {
        case STATIC_BORDER_COLOR_TRANSPARENT_BLACK: return vec4(0.0f);
        case STATIC_BORDER_COLOR_OPAQUE_BLACK: return vec4(0.0f, 0.0f, 0.0f, 1.0f);
        case STATIC_BORDER_COLOR_OPAQUE_WHITE: return vec4(1.0f);
    }
    return vec4(0.0f);
}

void validateSamplerDesc(const SamplerDesc& desc, const std::string& where) {
    switch (desc.Filter) {
        case FILTER_MIN_MAG_MIP_POINT:
        case FILTER_MIN_MAG_POINT_MIP_LINEAR:
        case FILTER_MIN_POINT_MAG_LINEAR_MIP_POINT:
        case FILTER_MIN_POINT_MAG_MIP_LINEAR:
        case FILTER_MIN_LINEAR_MAG_MIP_POINT:
        case FILTER_MIN_LINEAR_MAG_POINT_MIP_LINEAR:
        case FILTER_MIN_MAG_LINEAR_MIP_POINT:
        case FILTER_MIN_MAG_MIP_LINEAR:
        case FILTER_ANISOTROPIC: break;
        default:
            throw DxrError(diag("BIND-10", where + ": Filter is not a D3D12_FILTER refray models")
                               .hex("Filter", desc.Filter, "point/linear min, mag, mip or ANISOTROPIC (0x55)"));
    }
    const std::pair<const char*, TextureAddressMode> modes[] = {
        {"AddressU", desc.AddressU}, {"AddressV", desc.AddressV}, {"AddressW", desc.AddressW}};
    for (const auto& [field, mode] : modes)
        if (mode < TEXTURE_ADDRESS_MODE_WRAP || mode > TEXTURE_ADDRESS_MODE_MIRROR_ONCE)
            throw DxrError(diag("BIND-10", where + ": " + field + " is not a D3D12_TEXTURE_ADDRESS_MODE")
                               .value(field, uint32_t(mode), "1 (WRAP) .. 5 (MIRROR_ONCE)"));
    if (!(desc.MipLODBias >= -16.0f && desc.MipLODBias <= 15.99f))
        throw DxrError(diag("BIND-10", where + ": MipLODBias is outside the range D3D12 accepts")
                           .value("MipLODBias", desc.MipLODBias, "[-16, 15.99]"));
    if (desc.MaxAnisotropy > 16 || (desc.Filter == FILTER_ANISOTROPIC && desc.MaxAnisotropy == 0))
        throw DxrError(
            diag("BIND-10", where + ": MaxAnisotropy is outside the range D3D12 accepts")
                .value("MaxAnisotropy", desc.MaxAnisotropy, desc.Filter == FILTER_ANISOTROPIC ? "1..16" : "0..16"));
    if (std::isnan(desc.MinLOD) || std::isnan(desc.MaxLOD) || desc.MinLOD > desc.MaxLOD)
        throw DxrError(diag("BIND-10", where + ": MinLOD must not exceed MaxLOD (and neither may be NaN)")
                           .value("MinLOD", desc.MinLOD)
                           .value("MaxLOD", desc.MaxLOD));
    for (int c = 0; c < 4; ++c)
        if (std::isnan(desc.BorderColor[c]))
            throw DxrError(diag("BIND-10", where + ": BorderColor has a NaN component").value("component", c));
}

namespace {

// One TextureSystem for every Texture2D of the process. Private (not OpenImageIO's shared one), so nothing else in
// the process changes its settings. It is made with the first texture and lives as long as the process: OpenImageIO
// 2.4's TextureSystem::destroy frees it through a mismatched sized delete (AddressSanitizer reports a
// new-delete-type-mismatch inside libOpenImageIO). When the last texture goes, its caches are emptied instead, so
// no file stays open or cached.
OIIO::TextureSystem& processTextureSystem() {
    static OIIO::TextureSystem* const system = [] {
        OIIO::TextureSystem* ts = OIIO::TextureSystem::create(/*shared=*/false);
        ts->attribute("automip", 1);            // a full MIP chain for files without one
        ts->attribute("unassociatedalpha", 1);  // texels as stored: no premultiplication of PNG alpha
        return ts;
    }();
    return *system;
}

struct TextureSystemOwner {
    TextureSystemOwner() : system(&processTextureSystem()) {}
    ~TextureSystemOwner() { system->invalidate_all(/*force=*/true); }
    TextureSystemOwner(const TextureSystemOwner&) = delete;
    TextureSystemOwner& operator=(const TextureSystemOwner&) = delete;
    OIIO::TextureSystem* system;
};

std::shared_ptr<TextureSystemOwner> textureSystem() {
    static std::mutex mutex;
    static std::weak_ptr<TextureSystemOwner> current;
    std::lock_guard lock(mutex);
    std::shared_ptr<TextureSystemOwner> owner = current.lock();
    if (!owner) {
        owner = std::make_shared<TextureSystemOwner>();
        current = owner;
    }
    return owner;
}

// OpenImageIO's pending errors on one line.
std::string oiioMessage(const OIIO::TextureSystem& system) {
    std::string message = system.geterror();
    while (!message.empty() && message.back() == '\n') message.pop_back();
    for (size_t at = message.find('\n'); at != std::string::npos; at = message.find('\n', at))
        message.replace(at, 1, "; ");
    return message.empty() ? "OpenImageIO gave no message" : message;
}

float srgbToLinear(float c) { return c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f); }

// A texel coordinate as an integer; far-off coordinates saturate so the address arithmetic cannot overflow.
int64_t texelIndex(float coordinate) {
    constexpr double kLimit = double(int64_t(1) << 40);
    return int64_t(std::clamp(double(std::floor(coordinate)), -kLimit, kLimit));
}

// The D3D address modes on an integer texel coordinate of a level `size` texels long; -1 means the border.
int64_t address(TextureAddressMode mode, int64_t x, int64_t size) {
    switch (mode) {
        case TEXTURE_ADDRESS_MODE_WRAP: {
            const int64_t m = x % size;
            return m < 0 ? m + size : m;
        }
        case TEXTURE_ADDRESS_MODE_MIRROR: {
            int64_t m = x % (2 * size);
            if (m < 0) m += 2 * size;
            return m < size ? m : 2 * size - 1 - m;
        }
        case TEXTURE_ADDRESS_MODE_CLAMP: return std::clamp<int64_t>(x, 0, size - 1);
        case TEXTURE_ADDRESS_MODE_BORDER: return x < 0 || x >= size ? -1 : x;
        case TEXTURE_ADDRESS_MODE_MIRROR_ONCE: return std::min(x < 0 ? -x - 1 : x, size - 1);
    }
    return -1;
}

// OpenImageIO's wrap mode for a D3D address mode, where one means the same thing.
bool oiioWrap(TextureAddressMode mode, vec4 borderColor, OIIO::TextureOpt::Wrap& wrap) {
    switch (mode) {
        case TEXTURE_ADDRESS_MODE_WRAP: wrap = OIIO::TextureOpt::WrapPeriodic; return true;
        case TEXTURE_ADDRESS_MODE_MIRROR: wrap = OIIO::TextureOpt::WrapMirror; return true;
        case TEXTURE_ADDRESS_MODE_CLAMP: wrap = OIIO::TextureOpt::WrapClamp; return true;
        case TEXTURE_ADDRESS_MODE_BORDER:
            wrap = OIIO::TextureOpt::WrapBlack;  // transparent black only
            return borderColor == vec4(0.0f);
        case TEXTURE_ADDRESS_MODE_MIRROR_ONCE: return false;
    }
    return false;
}

}  // namespace

struct Texture2D::Impl {
    std::shared_ptr<TextureSystemOwner> owner;
    OIIO::TextureSystem* system = nullptr;
    OIIO::TextureSystem::TextureHandle* handle = nullptr;
    std::string path;
    bool sRGB = false;
    int fileChannels = 0;
    int readChannels = 0;       // min(fileChannels, 4)
    bool greyAlpha = false;     // two channels, the second alpha
    std::vector<ivec2> levels;  // size of each MIP level

    // Texels [x0, x1) x [y0, y1) of `level`, readChannels floats each, row by row.
    void read(int level, int x0, int x1, int y0, int y1, float* out) const {
        OIIO::TextureOpt options;
        if (!system->get_texels(handle, nullptr, options, level, x0, x1, y0, y1, 0, 1, 0, readChannels,
                                OIIO::TypeDesc::FLOAT, out))
            throw Error("texture '" + path + "': cannot read texels of MIP level " + std::to_string(level) + ": " +
                        oiioMessage(*system));
    }

    // File channels to RGBA (see texture.h), decoded from sRGB where the texture says so.
    vec4 expand(const float* c) const {
        vec4 v;
        switch (readChannels) {
            case 1: v = vec4(c[0], c[0], c[0], 1.0f); break;
            case 2: v = greyAlpha ? vec4(c[0], c[0], c[0], c[1]) : vec4(c[0], c[1], 0.0f, 1.0f); break;
            case 3: v = vec4(c[0], c[1], c[2], 1.0f); break;
            default: v = vec4(c[0], c[1], c[2], c[3]); break;
        }
        if (sRGB)
            for (int i = 0; i < 3; ++i) v[i] = srgbToLinear(v[i]);
        return v;
    }

    vec4 texel(int level, int64_t x, int64_t y) const {
        float c[4] = {};
        read(level, int(x), int(x) + 1, int(y), int(y) + 1, c);
        return expand(c);
    }

    vec4 point(const SamplerDesc& s, int level, vec2 uv) const {
        const ivec2 size = levels[size_t(level)];
        const int64_t x = address(s.AddressU, texelIndex(uv.x * float(size.x)), size.x);
        const int64_t y = address(s.AddressV, texelIndex(uv.y * float(size.y)), size.y);
        return x < 0 || y < 0 ? s.BorderColor : texel(level, x, y);
    }

    vec4 bilinear(const SamplerDesc& s, int level, vec2 uv) const {
        const ivec2 size = levels[size_t(level)];
        const float tx = uv.x * float(size.x) - 0.5f;
        const float ty = uv.y * float(size.y) - 0.5f;
        const float fx = std::floor(tx), fy = std::floor(ty);
        const float a = tx - fx, b = ty - fy;
        const int64_t x0 = texelIndex(fx), y0 = texelIndex(fy);
        const int64_t xs[2] = {address(s.AddressU, x0, size.x), address(s.AddressU, x0 + 1, size.x)};
        const int64_t ys[2] = {address(s.AddressV, y0, size.y), address(s.AddressV, y0 + 1, size.y)};
        vec4 t[2][2];  // [row][column]
        if (xs[0] >= 0 && xs[1] == xs[0] + 1 && ys[0] >= 0 && ys[1] == ys[0] + 1) {
            // The common case: one read for the 2x2 block.
            float c[16] = {};
            read(level, int(xs[0]), int(xs[0]) + 2, int(ys[0]), int(ys[0]) + 2, c);
            for (int j = 0; j < 2; ++j)
                for (int i = 0; i < 2; ++i) t[j][i] = expand(c + (2 * j + i) * readChannels);
        } else {
            for (int j = 0; j < 2; ++j)
                for (int i = 0; i < 2; ++i)
                    t[j][i] = xs[i] < 0 || ys[j] < 0 ? s.BorderColor : texel(level, xs[i], ys[j]);
        }
        return (1.0f - a) * (1.0f - b) * t[0][0] + a * (1.0f - b) * t[0][1] + (1.0f - a) * b * t[1][0] +
               a * b * t[1][1];
    }

    vec4 filterLevel(const SamplerDesc& s, bool linear, int level, vec2 uv) const {
        return linear ? bilinear(s, level, uv) : point(s, level, uv);
    }

    // Everything after the LOD is known: bias, clamps, MIN/MAG choice, MIP point or linear.
    vec4 sampleAtLod(const SamplerDesc& s, vec2 uv, float lod) const {
        if (std::isnan(uv.x)) uv.x = 0.0f;
        if (std::isnan(uv.y)) uv.y = 0.0f;
        if (std::isnan(lod)) lod = 0.0f;
        lod = std::min(std::max(lod + s.MipLODBias, s.MinLOD), s.MaxLOD);
        const uint32_t f = s.Filter;
        const bool linear = lod > 0.0f ? ((f >> 4) & 1u) != 0 : ((f >> 2) & 1u) != 0;
        const float level = std::clamp(lod, 0.0f, float(levels.size() - 1));
        if ((f & 1u) == 0) return filterLevel(s, linear, int(std::floor(level + 0.5f)), uv);
        const float l0 = std::floor(level);
        const float frac = level - l0;
        const vec4 c0 = filterLevel(s, linear, int(l0), uv);
        if (frac == 0.0f) return c0;
        return c0 * (1.0f - frac) + filterLevel(s, linear, int(l0) + 1, uv) * frac;
    }

    // log2 of the longer derivative, in texels of level 0.
    float gradientLod(vec2 ddx, vec2 ddy) const {
        const vec2 size(levels[0]);
        const vec2 x = ddx * size, y = ddy * size;
        return 0.5f * std::log2(std::max(x.x * x.x + x.y * x.y, y.x * y.x + y.y * y.y));
    }

    // OpenImageIO's elliptical filter; false where OpenImageIO cannot express the sampler.
    bool anisotropic(const SamplerDesc& s, vec2 uv, vec2 ddx, vec2 ddy, vec4& result) const {
        OIIO::TextureOpt options;
        if (!oiioWrap(s.AddressU, s.BorderColor, options.swrap) || !oiioWrap(s.AddressV, s.BorderColor, options.twrap))
            return false;
        const float lod = gradientLod(ddx, ddy);
        if (!std::isfinite(lod) || !std::isfinite(uv.x) || !std::isfinite(uv.y)) return false;
        // Bias and clamps move the footprint's size, not its shape.
        const float scale = std::exp2(std::min(std::max(lod + s.MipLODBias, s.MinLOD), s.MaxLOD) - lod);
        ddx *= scale;
        ddy *= scale;
        options.mipmode = OIIO::TextureOpt::MipModeAniso;
        options.interpmode = OIIO::TextureOpt::InterpBilinear;
        options.anisotropic = int(std::max(1u, s.MaxAnisotropy));
        float c[4] = {};
        if (!system->texture(handle, nullptr, options, uv.x, uv.y, ddx.x, ddx.y, ddy.x, ddy.y, readChannels, c))
            throw Error("texture '" + path + "': anisotropic lookup failed: " + oiioMessage(*system));
        result = expand(c);
        return true;
    }
};

Texture2D::Texture2D(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
Texture2D::~Texture2D() = default;

std::shared_ptr<const Texture2D> Texture2D::fromFile(const std::string& path, bool sRGB) {
    REFRAY_CHECK(!path.empty(), "Texture2D::fromFile needs a file name");
    checkInputFile(path, "texture", kMaxImageInputBytes);
    auto impl = std::make_unique<Impl>();
    impl->owner = textureSystem();
    impl->system = impl->owner->system;
    impl->path = path;
    impl->sRGB = sRGB;
    OIIO::TextureSystem& system = *impl->system;
    const OIIO::ustring name(path);

    // Forget what an earlier texture read from this file, so a rewritten file is read anew.
    system.invalidate(name, /*force=*/true);
    impl->handle = system.get_texture_handle(name);
    OIIO::ImageSpec spec;
    if (!impl->handle || !system.get_imagespec(impl->handle, nullptr, 0, spec))
        throw Error("texture '" + path + "': cannot open: " + oiioMessage(system));
    REFRAY_CHECK(uint64_t(spec.width) * uint64_t(spec.height) <= kMaxImagePixels,
                 "texture '" << path << "': its header declares " << spec.width << "x" << spec.height
                             << " pixels, more than the " << kMaxImagePixels
                             << " pixels (16384x16384) refray reads; a file that claims so much is corrupt or a "
                                "decompression bomb");
    REFRAY_CHECK(spec.depth <= 1, "texture '" << path << "' is a volume image (depth " << spec.depth
                                              << "); a Texture2D needs a 2D image");
    REFRAY_CHECK(spec.x == 0 && spec.y == 0, "texture '" << path << "' has a data window starting at (" << spec.x
                                                         << ", " << spec.y
                                                         << "); a Texture2D's texels start at (0, 0)");
    REFRAY_CHECK(spec.nchannels > 0, "texture '" << path << "' has no channels");
    impl->fileChannels = spec.nchannels;
    impl->readChannels = std::min(spec.nchannels, 4);
    impl->greyAlpha = spec.nchannels == 2 && spec.alpha_channel == 1;

    int levels = 0;
    if (!system.get_texture_info(impl->handle, nullptr, 0, OIIO::ustring("miplevels"), OIIO::TypeInt, &levels) ||
        levels < 1)
        throw Error("texture '" + path + "': cannot read its MIP levels: " + oiioMessage(system));
    for (int m = 0; m < levels; ++m) {
        OIIO::ImageSpec level;
        if (!system.imagecache()->get_imagespec(name, level, 0, m))
            throw Error("texture '" + path + "': cannot read MIP level " + std::to_string(m) + ": " +
                        oiioMessage(system));
        impl->levels.emplace_back(level.width, level.height);
    }

    // Read the first texel now: a truncated or corrupt file fails here rather than in a shader.
    float first[4] = {};
    impl->read(0, 0, 1, 0, 1, first);
    return std::shared_ptr<const Texture2D>(new Texture2D(std::move(impl)));
}

const std::string& Texture2D::path() const { return impl_->path; }
bool Texture2D::sRGB() const { return impl_->sRGB; }
uint32_t Texture2D::mipLevels() const { return uint32_t(impl_->levels.size()); }
uint32_t Texture2D::fileChannels() const { return uint32_t(impl_->fileChannels); }

uint32_t Texture2D::width(uint32_t mipLevel) const {
    return mipLevel < impl_->levels.size() ? uint32_t(impl_->levels[mipLevel].x) : 0;
}

uint32_t Texture2D::height(uint32_t mipLevel) const {
    return mipLevel < impl_->levels.size() ? uint32_t(impl_->levels[mipLevel].y) : 0;
}

vec4 Texture2D::SampleLevel(const SamplerDesc& sampler, vec2 location, float lod) const {
    return impl_->sampleAtLod(sampler, location, lod);
}

vec4 Texture2D::SampleGrad(const SamplerDesc& sampler, vec2 location, vec2 ddx, vec2 ddy) const {
    vec4 result;
    if (sampler.Filter == FILTER_ANISOTROPIC && impl_->anisotropic(sampler, location, ddx, ddy, result)) return result;
    return impl_->sampleAtLod(sampler, location, impl_->gradientLod(ddx, ddy));
}

vec4 Texture2D::Load(ivec2 texel, int mipLevel) const {
    if (mipLevel < 0 || size_t(mipLevel) >= impl_->levels.size()) return vec4(0.0f);
    const ivec2 size = impl_->levels[size_t(mipLevel)];
    if (texel.x < 0 || texel.y < 0 || texel.x >= size.x || texel.y >= size.y) return vec4(0.0f);
    return impl_->texel(mipLevel, texel.x, texel.y);
}

std::vector<vec4> Texture2D::readLevel(uint32_t mipLevel) const {
    REFRAY_CHECK(mipLevel < impl_->levels.size(), "texture '" << impl_->path << "' has " << impl_->levels.size()
                                                              << " MIP levels; level " << mipLevel << " was asked for");
    const ivec2 size = impl_->levels[mipLevel];
    const int channels = impl_->readChannels;
    std::vector<float> file(size_t(size.x) * size_t(size.y) * size_t(channels));
    impl_->read(int(mipLevel), 0, size.x, 0, size.y, file.data());
    std::vector<vec4> texels(size_t(size.x) * size_t(size.y));
    for (size_t i = 0; i < texels.size(); ++i) texels[i] = impl_->expand(file.data() + i * size_t(channels));
    return texels;
}

}  // namespace refray::dxr
