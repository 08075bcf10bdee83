// Samplers and read-only textures: D3D12 sampler descriptions and Texture2D shader resources read from image
// files through OpenImageIO's TextureSystem (which stays private to this file's .cpp).
//
// DXR ray-tracing shaders run without pixel quads, so they have no implicit derivatives and HLSL's Sample()
// does not exist in them. A shader reads a texture with SampleLevel (an explicit level of detail), SampleGrad
// (explicit derivatives) or Load (one texel); Texture2D offers exactly these three. The shader-facing handles
// that resolve registers (Texture2DRef, SamplerRef) are in shader_api.h; the rules for binding them (BIND-n)
// are in docs/emulator.md, "Resource binding (BIND)".
#pragma once

#include <cstdint>
#include <limits>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "core/math.h"

namespace refray::dxr {

// D3D12_FILTER values refray models: point or linear per min/mag/mip, and anisotropic. Comparison and
// min/max reduction filters are not modelled (SamplerDesc has no ComparisonFunc).
enum SamplerFilter : uint32_t {
    FILTER_MIN_MAG_MIP_POINT = 0x00,
    FILTER_MIN_MAG_POINT_MIP_LINEAR = 0x01,
    FILTER_MIN_POINT_MAG_LINEAR_MIP_POINT = 0x04,
    FILTER_MIN_POINT_MAG_MIP_LINEAR = 0x05,
    FILTER_MIN_LINEAR_MAG_MIP_POINT = 0x10,
    FILTER_MIN_LINEAR_MAG_POINT_MIP_LINEAR = 0x11,
    FILTER_MIN_MAG_LINEAR_MIP_POINT = 0x14,
    FILTER_MIN_MAG_MIP_LINEAR = 0x15,
    FILTER_ANISOTROPIC = 0x55,
};

// D3D12_TEXTURE_ADDRESS_MODE: what a coordinate outside [0, 1] reads.
enum TextureAddressMode : uint32_t {
    TEXTURE_ADDRESS_MODE_WRAP = 1,
    TEXTURE_ADDRESS_MODE_MIRROR = 2,
    TEXTURE_ADDRESS_MODE_CLAMP = 3,
    TEXTURE_ADDRESS_MODE_BORDER = 4,
    TEXTURE_ADDRESS_MODE_MIRROR_ONCE = 5,
};

// D3D12_STATIC_BORDER_COLOR: the border colours a static sampler may use.
enum StaticBorderColor : uint32_t {
    STATIC_BORDER_COLOR_TRANSPARENT_BLACK = 0,
    STATIC_BORDER_COLOR_OPAQUE_BLACK = 1,
    STATIC_BORDER_COLOR_OPAQUE_WHITE = 2,
};

std::string_view toString(SamplerFilter filter);
std::string_view toString(TextureAddressMode mode);
vec4 toColor(StaticBorderColor color);

// D3D12_SAMPLER_DESC without ComparisonFunc: what a sampler descriptor holds. Static samplers of a root
// signature (StaticSamplerDesc, root_signature.h) resolve to one of these.
struct SamplerDesc {
    SamplerFilter Filter = FILTER_MIN_MAG_MIP_LINEAR;
    TextureAddressMode AddressU = TEXTURE_ADDRESS_MODE_WRAP;
    TextureAddressMode AddressV = TEXTURE_ADDRESS_MODE_WRAP;
    TextureAddressMode AddressW = TEXTURE_ADDRESS_MODE_WRAP;
    float MipLODBias = 0.0f;      // [-16, 15.99]
    uint32_t MaxAnisotropy = 16;  // [1, 16] for FILTER_ANISOTROPIC, at most 16 otherwise
    vec4 BorderColor{0.0f};       // TEXTURE_ADDRESS_MODE_BORDER reads this colour
    float MinLOD = 0.0f;
    float MaxLOD = std::numeric_limits<float>::max();  // D3D12_FLOAT32_MAX: no upper clamp
};

// Throws DxrError BIND-10 naming `where` and the field when `desc` is not a sampler D3D12 would create: an
// unknown filter or address mode, MipLODBias outside [-16, 15.99], MaxAnisotropy above 16 (or 0 with
// FILTER_ANISOTROPIC), MinLOD > MaxLOD, or a NaN.
void validateSamplerDesc(const SamplerDesc& desc, const std::string& where);

// A read-only 2D texture (a Texture2D<float4> SRV) whose texels come from an image file (PNG, EXR, TIFF, JPEG,
// HDR, ... whatever OpenImageIO reads). Immutable once made, so every worker thread may sample it at once; all
// textures share one private OpenImageIO TextureSystem (thread-safe, with a bounded tile cache).
//
// Texels: 8- and 16-bit files read as UNORM (value / 255 or / 65535), float files as stored. Every file reads
// as an app that expands it to four channels uploads it (stb_image with 4 components): grey (g) is (g, g, g, 1),
// grey+alpha (g, a) is (g, g, g, a), two channels without alpha (r, g) are (r, g, 0, 1), RGB is (r, g, b, 1);
// channels past the fourth are ignored. Alpha is never premultiplied. With `sRGB` the texture behaves as a *_SRGB
// format: colour channels are decoded to linear per texel before filtering (alpha is not).
//
// MIP levels: a file's own levels, or, for a file without them, a full chain made on the fly by the
// TextureSystem ("automip"): level m is max(1, width >> m) by max(1, height >> m), each texel the bilinear
// average of the finer level at its centre (the 2x2 box average when the finer size is even), stored in the
// file's format (8-bit files get 8-bit levels, as an app uploading UNORM8 levels would).
//
// Sampling follows the D3D11.3 functional spec (section 7.18), the rules D3D12 inherits:
// - coordinates: u = 0 is the left edge and v = 0 the top row; texel i covers [i, i + 1) / size, its centre at
//   (i + 0.5) / size; point filtering reads texel floor(u * size), linear filtering the 2x2 texels around
//   u * size - 0.5 with weights from the fraction.
// - address modes act on integer texel coordinates: WRAP (modulo), MIRROR (period 2 * size), CLAMP, BORDER
//   (the sampler's BorderColor for texels outside the level), MIRROR_ONCE (mirror once about 0, then clamp).
// - level of detail: lod (SampleLevel) or log2 of the longer derivative in texels of level 0 (SampleGrad), then
//   + MipLODBias, clamped to [MinLOD, MaxLOD] and to the levels present. lod <= 0 magnifies (the MAG filter),
//   lod > 0 minifies (the MIN filter). MIP point picks level floor(lod + 0.5); MIP linear blends levels
//   floor(lod) and floor(lod) + 1 by the fraction. A NaN coordinate or lod counts as 0.
// - FILTER_ANISOTROPIC: SampleLevel filters as MIN_MAG_MIP_LINEAR (there are no derivatives to orient a
//   footprint). SampleGrad uses OpenImageIO's elliptical (anisotropic, bilinear-probe) filter with at most
//   MaxAnisotropy probes; D3D leaves the anisotropic filter's exact footprint to the implementation. Bias and
//   LOD clamps scale the derivatives. OpenImageIO has no MIRROR_ONCE and no opaque border colours: with those
//   address modes SampleGrad filters as MIN_MAG_MIP_LINEAR at the derivative LOD instead. With `sRGB` the
//   anisotropic result is decoded after filtering (an approximation: the hardware decodes each texel).
//
// Results depend only on the file, the sampler and the arguments, never on threads or cache state.
class Texture2D {
public:
    // Opens `path` and reads its header and first tile, so a missing or unreadable file fails here and not
    // at the first sample: throws refray::Error naming the file and OpenImageIO's message. Also refused: volume
    // images and images whose data window does not start at pixel (0, 0). A file rewritten since an earlier
    // Texture2D read it is read again (which the earlier Texture2D also sees).
    static std::shared_ptr<const Texture2D> fromFile(const std::string& path, bool sRGB = false);
    ~Texture2D();
    Texture2D(const Texture2D&) = delete;
    Texture2D& operator=(const Texture2D&) = delete;

    const std::string& path() const;
    bool sRGB() const;
    // Level sizes (0 for a level past the last) and the number of levels.
    uint32_t width(uint32_t mipLevel = 0) const;
    uint32_t height(uint32_t mipLevel = 0) const;
    uint32_t mipLevels() const;
    // Channels in the file (before the expansion to four described above).
    uint32_t fileChannels() const;

    // HLSL Texture2D.SampleLevel(sampler, location, lod). `sampler` must be valid (validateSamplerDesc).
    // Throws refray::Error if the file cannot be read any more (removed or changed since fromFile).
    vec4 SampleLevel(const SamplerDesc& sampler, vec2 location, float lod) const;
    // HLSL Texture2D.SampleGrad(sampler, location, ddx, ddy): ddx and ddy are d(location)/dx and d(location)/dy.
    vec4 SampleGrad(const SamplerDesc& sampler, vec2 location, vec2 ddx, vec2 ddy) const;
    // HLSL Texture2D.Load(int3(texel, mipLevel)): one texel, no filtering or addressing. A texel or level out of
    // range reads (0, 0, 0, 0), as D3D defines.
    vec4 Load(ivec2 texel, int mipLevel = 0) const;
    // Every texel of MIP level `mipLevel` as Load returns it (RGBA, sRGB decoded where the texture says so), row by
    // row from the top: what a back end uploads so that its sampler filters the same texels. Throws refray::Error
    // for a level past the last or a file that cannot be read any more.
    std::vector<vec4> readLevel(uint32_t mipLevel) const;

private:
    struct Impl;
    explicit Texture2D(std::unique_ptr<Impl> impl);
    std::unique_ptr<Impl> impl_;
};

using Texture2DPtr = std::shared_ptr<const Texture2D>;

}  // namespace refray::dxr
