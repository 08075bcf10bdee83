// Ports refray's C++ procedural/pathtracer/pt_math.h (the path tracer's pure math; refray's own, no HLSL original)
// and pcgHash of core/random.h, function by function with the C++ names. The C++ templates on the scalar type;
// the shaders instantiate float, which is all this port has. See PORTING.md.
#ifndef PT_MATH_GLSL
#define PT_MATH_GLSL

const float kPi = 3.14159265358979323846;

// ---- Random numbers (core/random.h pcgHash; pt_math.h PathRng) -------------------------------------------------
// The same integer arithmetic as the C++ (uint wraps modulo 2^32 in both), so a pixel's stream of numbers is the
// C++'s own: the GPU draws the numbers the emulator draws.

uint pcgHash(uint v) {
    const uint state = v * 747796405u + 2891336453u;
    const uint word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
    return (word >> 22u) ^ word;
}

// PORT: PathRng is a struct of one uint in the C++; here the uint itself, passed inout.
uint makePathRng(uint x, uint y, uint sampleIndex, uint seed) {
    return pcgHash(x + pcgHash(y + pcgHash(sampleIndex + pcgHash(seed))));
}

uint nextUint(inout uint rng) {
    rng = rng * 747796405u + 2891336453u;
    const uint word = ((rng >> ((rng >> 28u) + 4u)) ^ rng) * 277803737u;
    return (word >> 22u) ^ word;
}

// Uniform in [0, 1): the top 24 bits times 2^-24, exact in float.
float nextUniform(inout uint rng) { return float(nextUint(rng) >> 8u) * (1.0 / 16777216.0); }

// ---- Frames --------------------------------------------------------------------------------------------------

// PORT: std::copysign(1, n.z) reads the sign bit, so -0 gives -1; GLSL sign() would give 0.
float copysignOne(float x) { return (floatBitsToUint(x) & 0x80000000u) != 0u ? -1.0 : 1.0; }

// t, b such that (t, b, n) is a right-handed orthonormal basis for the unit vector n (Duff et al. 2017).
void orthonormalBasis(vec3 n, out vec3 t, out vec3 b) {
    const float sign = copysignOne(n.z);
    const float a = -1.0 / (sign + n.z);
    const float c = n.x * n.y * a;
    t = vec3(1.0 + sign * n.x * n.x * a, sign * c, -sign * n.x);
    b = vec3(c, sign + n.y * n.y * a, -n.y);
}

vec3 fromLocal(vec3 local, vec3 n) {
    vec3 t, b;
    orthonormalBasis(n, t, b);
    return local.x * t + local.y * b + local.z * n;
}

// ---- Cosine-weighted hemisphere ------------------------------------------------------------------------------

vec3 sampleCosineHemisphere(float u1, float u2) {
    const float r = sqrt(u1);
    const float phi = 2.0 * kPi * u2;
    return vec3(r * cos(phi), r * sin(phi), sqrt(max(0.0, 1.0 - u1)));
}

float cosineHemispherePdf(float cosTheta) { return cosTheta > 0.0 ? cosTheta / kPi : 0.0; }

// ---- The glossy lobe: normalized modified Phong ------------------------------------------------------------------
// GLSL pow(x, y) is undefined for x < 0 and for x = 0 with y <= 0; every call below has x > 0, as in the C++.

float phongLobePdf(float cosAlpha, float exponent) {
    return cosAlpha > 0.0 ? (exponent + 1.0) / (2.0 * kPi) * pow(cosAlpha, exponent) : 0.0;
}

float phongLobeBrdf(float cosAlpha, float exponent) {
    return cosAlpha > 0.0 ? (exponent + 2.0) / (2.0 * kPi) * pow(cosAlpha, exponent) : 0.0;
}

vec3 samplePhongLobe(float u1, float u2, float exponent) {
    const float cosAlpha = pow(1.0 - u1, 1.0 / (exponent + 1.0));  // 1 - u1 in (0, 1]
    const float sinAlpha = sqrt(max(0.0, 1.0 - cosAlpha * cosAlpha));
    const float phi = 2.0 * kPi * u2;
    return vec3(sinAlpha * cos(phi), sinAlpha * sin(phi), cosAlpha);
}

// ---- The material's BSDF: Lambert + Phong ------------------------------------------------------------------

struct SurfaceBsdf {
    vec3 diffuse;   // Kd times the diffuse texture
    vec3 specular;  // Ks
    float exponent; // Ns
    float specularProbability;
};

// PORT: std::max({x, y, z}) is max(max(x, y), z) here; they differ only for NaN, which no material holds.
float maxComponent(vec3 v) { return max(max(v.x, v.y), v.z); }

SurfaceBsdf makeSurfaceBsdf(vec3 diffuse, vec3 specular, float exponent) {
    SurfaceBsdf bsdf;
    const vec3 sum = diffuse + specular;
    const float largest = maxComponent(sum);
    const float scale = largest > 1.0 ? 1.0 / largest : 1.0;
    bsdf.diffuse = diffuse * scale;
    bsdf.specular = specular * scale;
    bsdf.exponent = max(0.0, exponent);
    const float d = bsdf.diffuse.x + bsdf.diffuse.y + bsdf.diffuse.z;
    const float s = bsdf.specular.x + bsdf.specular.y + bsdf.specular.z;
    bsdf.specularProbability = s > 0.0 ? s / (d + s) : 0.0;
    return bsdf;
}

bool isBlack(SurfaceBsdf bsdf) { return bsdf.diffuse == vec3(0.0) && bsdf.specular == vec3(0.0); }

// The mirror direction of wo (pointing away from the surface); GLSL's reflect() takes the incident direction.
vec3 mirror(vec3 wo, vec3 n) { return 2.0 * dot(n, wo) * n - wo; }

vec3 evalBsdf(SurfaceBsdf bsdf, vec3 n, vec3 wo, vec3 wi) {
    if (dot(n, wo) <= 0.0 || dot(n, wi) <= 0.0) return vec3(0.0);
    vec3 f = bsdf.diffuse / kPi;
    if (bsdf.specularProbability > 0.0) f += bsdf.specular * phongLobeBrdf(dot(mirror(wo, n), wi), bsdf.exponent);
    return f;
}

float bsdfPdf(SurfaceBsdf bsdf, vec3 n, vec3 wo, vec3 wi) {
    const float ps = bsdf.specularProbability;
    float pdf = (1.0 - ps) * cosineHemispherePdf(dot(n, wi));
    if (ps > 0.0) pdf += ps * phongLobePdf(dot(mirror(wo, n), wi), bsdf.exponent);
    return pdf;
}

struct BsdfSample {
    vec3 wi;
    float pdf;
    vec3 weight;  // f cos / pdf
};

BsdfSample sampleBsdf(SurfaceBsdf bsdf, vec3 n, vec3 wo, float u0, float u1, float u2) {
    BsdfSample s = BsdfSample(vec3(0.0), 0.0, vec3(0.0));
    if (u0 < bsdf.specularProbability)
        s.wi = fromLocal(samplePhongLobe(u1, u2, bsdf.exponent), mirror(wo, n));
    else
        s.wi = fromLocal(sampleCosineHemisphere(u1, u2), n);
    s.pdf = bsdfPdf(bsdf, n, wo, s.wi);
    const float cosTheta = dot(n, s.wi);
    if (s.pdf > 0.0 && cosTheta > 0.0) s.weight = evalBsdf(bsdf, n, wo, s.wi) * (cosTheta / s.pdf);
    return s;
}

// ---- Triangles -----------------------------------------------------------------------------------------------

float triangleArea(vec3 v0, vec3 v1, vec3 v2) { return 0.5 * length(cross(v1 - v0, v2 - v0)); }

vec3 sampleTriangleUniform(vec3 v0, vec3 v1, vec3 v2, float u1, float u2) {
    const float su = sqrt(u1);
    const float b0 = 1.0 - su, b1 = u2 * su;
    return b0 * v0 + b1 * v1 + (1.0 - b0 - b1) * v2;
}

float triangleAreaPdf(float area) { return area > 0.0 ? 1.0 / area : 0.0; }

// ---- Next-event estimation and MIS --------------------------------------------------------------------------

float areaToSolidAnglePdf(float pdfArea, float distance, float cosLight) {
    const float c = abs(cosLight);
    return c > 0.0 ? pdfArea * distance * distance / c : 0.0;
}

float powerHeuristic(float pdfThis, float pdfOther) {
    const float a = pdfThis * pdfThis, b = pdfOther * pdfOther;
    return a > 0.0 ? a / (a + b) : 0.0;
}

// ---- Russian roulette ----------------------------------------------------------------------------------------

const uint kRussianRouletteStartBounce = 3u;
const float kRussianRouletteMaxSurvival = 0.95;

float russianRouletteSurvival(vec3 throughput) { return min(maxComponent(throughput), kRussianRouletteMaxSurvival); }

bool russianRoulette(inout vec3 throughput, float u) {
    const float q = russianRouletteSurvival(throughput);
    if (!(q > 0.0) || u >= q) return false;
    throughput /= q;
    return true;
}

#endif  // PT_MATH_GLSL
