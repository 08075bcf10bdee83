// Tests procedural/math/fractals.h over lanes: with T = Lanes<float, W> (W = 16 and 8) lane i of every result (hit flag, t,
// normal, orbit trap, position, iteration count) is bit for bit the T = float result for lane i's inputs, whatever
// the other lanes hold. Seeded inputs mix rays that hit, miss and graze, so every lane mask is exercised; some
// groups hold a few real rays among NaN/infinite/garbage lanes. PerturbedFloat must still instantiate every function.
#ifndef REFRAY_LANES_TEST_WIDTH
#define REFRAY_LANES_TEST_WIDTH 16
#endif

#include "procedural/math/fractals.h"
#include "procedural/math/perturbed.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <vector>

#include <gtest/gtest.h>

namespace refray::procedural::math {

// tests/procedural/CMakeLists.txt builds this file for 16 lanes (kMaxLanes) and for 8 (the ports').
constexpr int kTestLanes = REFRAY_LANES_TEST_WIDTH;
using L = Lanes<float, kTestLanes>;

// ---- Workarounds for the functions outside fractals.h that do not compile for lanes yet ------------------------
// Non-template overloads for L in this namespace, found by argument-dependent lookup when the templates are
// instantiated (a better match than the templates). They go once analytic.h and hlsl.h handle lanes themselves.
//
// analytic.h isphere: `if (h < T(0)) return ...` needs a bool. The same computation with the miss as a select.
inline vec2<L> isphere(const vec4<L>& sph, const vec3<L>& ro, const vec3<L>& rd) {
    const vec3<L> oc = ro - vec3<L>(sph);
    const L b = hlsl::dot(oc, rd);
    const L c = hlsl::dot(oc, oc) - sph.w * sph.w;
    L h = b * b - c;
    const LaneMask<L> miss = h < L(0);
    h = hlsl::sqrt(h);
    return select(miss, vec2<L>(L(-1), L(-1)), -b + vec2<L>(-h, h));
}
// hlsl.h's vector fmod calls `fmod(a, b)` unqualified, and the lanes overload in lanes.h is declared after it (and
// in namespace hlsl, which ADL does not search for Lanes): the scalar template's `q >= -q ? f : -f` is picked and
// does not compile. This forwards to the lanes overload (opRep: MiniSpheres, Cog, Cylinder).
inline L fmod(L x, L y) { return hlsl::fmod(x, y); }

namespace {

using P = PerturbedFloat;

// ---- Flattening a result to its bits, for one lane ------------------------------------------------------------
using Bits = std::vector<std::uint32_t>;

void put(Bits& out, float x, int) { out.push_back(std::bit_cast<std::uint32_t>(x)); }
void put(Bits& out, const L& x, int i) { out.push_back(std::bit_cast<std::uint32_t>(lane(x, i))); }
void put(Bits& out, bool m, int) { out.push_back(m ? 1u : 0u); }
void put(Bits& out, const LaneBools<kTestLanes>& m, int i) { out.push_back(lane(m, i) ? 1u : 0u); }
template <glm::length_t K, class T>
void put(Bits& out, const glm::vec<K, T>& v, int i) {
    for (glm::length_t k = 0; k < K; ++k) put(out, v[k], i);
}

// The inputs of one call: two vectors and a scalar (ro, rd, mouth / position, normal, ...).
template <class T>
struct Input {
    using Scalar = T;
    vec3<T> a{};
    vec3<T> b{};
    T s{};
};

Input<L> gather(const std::vector<Input<float>>& in, size_t first) {
    Input<L> g;
    for (int i = 0; i < kTestLanes; ++i) {
        const Input<float>& x = in[(first + size_t(i)) % in.size()];
        setLane(g.a, i, x.a);
        setLane(g.b, i, x.b);
        setLane(g.s, i, x.s);
    }
    return g;
}

// Lanes that hold no ray: NaN, infinities, zero, huge and denormal values.
Input<float> garbage(std::mt19937& rng) {
    const float nan = std::numeric_limits<float>::quiet_NaN();
    const float inf = std::numeric_limits<float>::infinity();
    const float pool[] = {nan, inf, -inf, 0.0f, -0.0f, 1e30f, -1e30f, 1e-40f, 3.0f, -7.5f};
    std::uniform_int_distribution<int> pick(0, int(std::size(pool)) - 1);
    Input<float> g;
    for (int k = 0; k < 3; ++k) {
        g.a[k] = pool[pick(rng)];
        g.b[k] = pool[pick(rng)];
    }
    g.s = pool[pick(rng)];
    return g;
}

// Runs `fn` on every input alone (T = float) and in groups of kTestLanes (T = L), and compares lane i of the group's result
// with the scalar result bit for bit. `isHit` tells a hit from a scalar result; returns how many groups mix hits
// and misses. With `withGarbage`, a second pass puts the real inputs in a few lanes only (a different pattern per
// group) and garbage in the others, and checks the real lanes.
template <class Fn, class Flat, class IsHit>
int checkLanes(const char* name, const std::vector<Input<float>>& inputs, Fn fn, Flat flat, IsHit isHit,
               bool withGarbage = true) {
    std::vector<Bits> expected(inputs.size());
    std::vector<bool> hits(inputs.size());
    for (size_t k = 0; k < inputs.size(); ++k) {
        const auto r = fn(inputs[k]);
        flat(expected[k], r, 0);
        hits[k] = isHit(r);
    }
    int mixedGroups = 0;
    for (size_t first = 0; first < inputs.size(); first += kTestLanes) {
        const auto r = fn(gather(inputs, first));
        int groupHits = 0;
        for (int i = 0; i < kTestLanes; ++i) {
            const size_t k = (first + size_t(i)) % inputs.size();
            Bits got;
            flat(got, r, i);
            EXPECT_EQ(got, expected[k]) << name << ": input " << k << " in lane " << i;
            groupHits += hits[k] ? 1 : 0;
        }
        if (groupHits > 0 && groupHits < kTestLanes) ++mixedGroups;
    }
    if (withGarbage) {
        std::mt19937 rng(977);
        size_t next = 0;
        for (int group = 0; next < inputs.size() && group < 12; ++group) {
            // A few real lanes, in a pattern that changes with the group.
            std::vector<Input<float>> lanes(kTestLanes);
            std::vector<size_t> real(kTestLanes, SIZE_MAX);
            for (int i = 0; i < kTestLanes; ++i) {
                if ((i * 7 + group) % 5 == 0 && next < inputs.size()) {
                    real[size_t(i)] = next;
                    lanes[size_t(i)] = inputs[next++];
                } else {
                    lanes[size_t(i)] = garbage(rng);
                }
            }
            const auto r = fn(gather(lanes, 0));
            for (int i = 0; i < kTestLanes; ++i) {
                if (real[size_t(i)] == SIZE_MAX) continue;
                Bits got;
                flat(got, r, i);
                EXPECT_EQ(got, expected[real[size_t(i)]])
                    << name << " (garbage in the other lanes): input " << real[size_t(i)] << " in lane " << i;
            }
        }
    }
    return mixedGroups;
}

constexpr auto kNoHit = [](const auto&) { return false; };

float uniform(std::mt19937& rng, float lo, float hi) { return std::uniform_real_distribution<float>(lo, hi)(rng); }

glm::vec3 unitVector(std::mt19937& rng) {
    for (;;) {
        const glm::vec3 d(uniform(rng, -1, 1), uniform(rng, -1, 1), uniform(rng, -1, 1));
        const float l2 = glm::dot(d, d);
        if (l2 > 1e-3f && l2 <= 1.0f) return d / std::sqrt(l2);
    }
}

glm::vec3 normalized(const glm::vec3& v) { return v / std::sqrt(glm::dot(v, v)); }

// Rays at a ball of radius `radius` about `centre`: aimed inside it (most hit), beside it (miss), tangent to it
// (graze), and some starting inside it.
std::vector<Input<float>> raysAtBall(std::uint32_t seed, int count, const glm::vec3& centre, float radius) {
    std::mt19937 rng(seed);
    std::vector<Input<float>> rays;
    for (int k = 0; k < count; ++k) {
        Input<float> in;
        const glm::vec3 ro = centre + unitVector(rng) * (radius * uniform(rng, 1.05f, 3.0f));
        glm::vec3 target;
        switch (k % 4) {
            case 0:
            case 1: target = centre + unitVector(rng) * (radius * uniform(rng, 0.0f, 1.1f)); break;
            case 2: {  // grazing: the closest approach is the radius within a tiny margin
                const glm::vec3 toC = normalized(centre - ro);
                glm::vec3 side = normalized(glm::cross(toC, unitVector(rng)));
                const float dist = std::sqrt(glm::dot(centre - ro, centre - ro));
                const float r = radius * (1.0f + uniform(rng, -1e-4f, 1e-4f));
                const float sinA = r / dist;
                const glm::vec3 dir = toC * std::sqrt(1.0f - sinA * sinA) + side * sinA;
                target = ro + dir;
                break;
            }
            default:
                if (k % 8 == 3) {
                    in.a = centre + unitVector(rng) * (radius * uniform(rng, 0.0f, 0.9f));  // starts inside
                    in.b = unitVector(rng);
                    in.s = uniform(rng, 0, 1);
                    rays.push_back(in);
                    continue;
                }
                target = centre + unitVector(rng) * (radius * uniform(rng, 1.2f, 2.0f));  // misses
        }
        in.a = ro;
        in.b = normalized(target - ro);
        in.s = uniform(rng, 0, 1);
        rays.push_back(in);
    }
    return rays;
}

// Positions in a box of half-size `extent` and on a sphere of radius `shell` (near a surface), with a unit vector
// in b and a number in [0, 1] in s.
std::vector<Input<float>> positions(std::uint32_t seed, int count, float extent, float shell) {
    std::mt19937 rng(seed);
    std::vector<Input<float>> out;
    for (int k = 0; k < count; ++k) {
        Input<float> in;
        if (k % 3 == 0) {
            in.a = unitVector(rng) * (shell * (1.0f + uniform(rng, -0.02f, 0.02f)));
        } else {
            in.a = glm::vec3(uniform(rng, -extent, extent), uniform(rng, -extent, extent),
                             uniform(rng, -extent, extent));
        }
        in.b = unitVector(rng);
        in.s = uniform(rng, 0, 1);
        out.push_back(in);
    }
    return out;
}

// ---- Mandelbulb -------------------------------------------------------------------------------------------------
TEST(LanesFractals, MandelbulbDistanceMatchesScalarPerLane) {
    const std::vector<Input<float>> rays = raysAtBall(11, 256, glm::vec3(0), 1.25f);
    const auto flat = [](Bits& b, const auto& r, int i) {
        put(b, r.hit, i);
        put(b, r.thit, i);
        put(b, r.normal, i);
        put(b, r.color, i);
        put(b, r.pos, i);
    };
    const auto isHit = [](const mandelbulb::MandelbulbHit<float>& r) { return r.hit; };
    for (const int iMax : {1, 7, 40, 129}) {
        const auto fn = [iMax](const auto& in) { return mandelbulb::MandelbulbDistance(in.a, in.b, iMax); };
        EXPECT_GT(checkLanes("MandelbulbDistance", rays, fn, flat, isHit), 0) << "iMax " << iMax;
    }
    // Other constants (the accuracy knobs): a coarse threshold, more mdist iterations, a larger normal offset.
    const auto fnKnobs = [](const auto& in) {
        using T = typename std::decay_t<decltype(in)>::Scalar;
        mandelbulb::MandelbulbParams<T> params;
        params.threshold = T(0.01f);
        params.iterations = 7;
        params.normalOffset = T(1e-3f);
        return mandelbulb::MandelbulbDistance(in.a, in.b, 60, params);
    };
    EXPECT_GT(checkLanes("MandelbulbDistance(params)", rays, fnKnobs, flat, isHit), 0);
}

TEST(LanesFractals, MandelbulbQueuesGiveEachRayItsScalarResult) {
    // MandelbulbDistanceQueue refills its lanes from a queue of up to 16 rays: every ray's result (hit, t, normal,
    // orbit trap, last sample) is bit for bit the one-ray result, for every queue length 1..16, with rays that miss
    // the bounding sphere (raysAtBall's spread puts some outside), rays that run out of steps (iMax 7), no steps at
    // all (iMax 0: a ray inside the sphere hits at its entry, with calcNormal at the origin: NaN, H4), and the
    // accuracy knobs' constants.
    const std::vector<Input<float>> rays = raysAtBall(13, 200, glm::vec3(0), 1.6f);
    mandelbulb::MandelbulbParams<float> knobs;
    knobs.threshold = 0.01f;
    knobs.iterations = 7;
    knobs.normalOffset = 1e-3f;
    int missed = 0, hits = 0, queues = 0;
    for (const auto& [iMax, params] : {std::pair{129, mandelbulb::MandelbulbParams<float>{}},
                                       std::pair{7, mandelbulb::MandelbulbParams<float>{}}, std::pair{0, knobs},
                                       std::pair{60, knobs}}) {
        size_t first = 0;
        for (int count = 1; first < rays.size(); count = count % kMaxMarchQueue + 1) {
            const int n = int(std::min<size_t>(size_t(count), rays.size() - first));
            std::vector<glm::vec3> ro(static_cast<size_t>(n)), rd(static_cast<size_t>(n));
            std::vector<mandelbulb::MandelbulbHit<float>> got(static_cast<size_t>(n));
            for (int k = 0; k < n; ++k) {
                ro[size_t(k)] = rays[first + size_t(k)].a;
                rd[size_t(k)] = rays[first + size_t(k)].b;
            }
            mandelbulb::MandelbulbDistanceQueue<L>(ro.data(), rd.data(), n, iMax, got.data(), params);
            ++queues;
            for (int k = 0; k < n; ++k) {
                const mandelbulb::MandelbulbHit<float> want =
                    mandelbulb::MandelbulbDistance(ro[size_t(k)], rd[size_t(k)], iMax, params);
                const auto flat = [](const mandelbulb::MandelbulbHit<float>& r) {
                    Bits out;
                    put(out, r.hit, 0);
                    put(out, r.thit, 0);
                    put(out, r.normal, 0);
                    put(out, r.color, 0);
                    put(out, r.pos, 0);
                    return out;
                };
                EXPECT_EQ(flat(got[size_t(k)]), flat(want)) << "MandelbulbDistanceQueue: ray " << first + size_t(k) << " of a queue of " << n
                                << ", iMax " << iMax;
                missed += mandelbulb::mandelbulbBounds(ro[size_t(k)], rd[size_t(k)]).inSphere ? 0 : 1;
                hits += want.hit ? 1 : 0;
            }
            first += size_t(n);
        }
    }
    EXPECT_GT(missed, 0);
    EXPECT_GT(hits, 0);
    EXPECT_GT(queues, 40);
}

TEST(LanesFractals, MandelbulbMdistAndNormalMatchScalarPerLane) {
    std::vector<Input<float>> pts = positions(12, 320, 1.3f, 1.0f);
    pts[5].a = glm::vec3(0);           // NaN (H4)
    pts[6].a = glm::vec3(0, 0.7f, 0);  // on the y axis (H5)
    for (const int iterations : {1, 4, 9}) {
        const auto fn = [iterations](const auto& in) {
            using T = typename std::decay_t<decltype(in)>::Scalar;
            vec4<T> color;
            const T d = mandelbulb::mdist(in.a, color, iterations);
            return std::make_pair(d, color);
        };
        const auto flat = [](Bits& b, const auto& r, int i) {
            put(b, r.first, i);
            put(b, r.second, i);
        };
        // "Hit" here: the orbit escaped (m > 256), so groups mix escaping and bounded orbits.
        const auto escaped = [](const std::pair<float, glm::vec4>& r) { return r.second.x > 256.0f; };
        const int mixed = checkLanes("mdist", pts, fn, flat, escaped);
        if (iterations > 1) {
            EXPECT_GT(mixed, 0) << "iterations " << iterations;
        }
    }
    const auto normal = [](const auto& in) {
        using T = typename std::decay_t<decltype(in)>::Scalar;
        return mandelbulb::calcNormal(in.a, T(in.s) * T(1e-3f) + tetrahedralOffset<T>());
    };
    checkLanes("mandelbulb::calcNormal", pts, normal, [](Bits& b, const auto& r, int i) { put(b, r, i); }, kNoHit);
}

// ---- Julia --------------------------------------------------------------------------------------------------------
// Local-space rays: q = 0.4*ro + (0, -1, 0), so the q-space ball of radius 1.2 is the local ball of radius 3 about
// (0, 2.5, 0). Some rays are horizontal (rd.y = 0, H10) and some start between the cut planes.
std::vector<Input<float>> juliaRays(std::uint32_t seed, int count) {
    std::vector<Input<float>> rays = raysAtBall(seed, count, glm::vec3(0, 2.5f, 0), 3.0f);
    for (size_t k = 0; k < rays.size(); k += 7) {
        rays[k].b.y = 0;
        rays[k].b = normalized(rays[k].b);
    }
    return rays;
}

TEST(LanesFractals, JuliaDistanceMatchesScalarPerLane) {
    const std::vector<Input<float>> rays = juliaRays(21, 192);
    const auto flat = [](Bits& b, const auto& r, int i) {
        put(b, r.hit, i);
        put(b, r.normal, i);
        put(b, r.resT, i);
    };
    const auto isHit = [](const julia::JuliaHit<float>& r) { return r.hit; };
    const auto fn = [](const auto& in) { return julia::JuliaDistance(in.a, in.b); };
    EXPECT_GT(checkLanes("JuliaDistance", rays, fn, flat, isHit), 0);
    // Few march steps (running out of steps counts as a hit, H15), fewer jdist iterations, a coarse stop test.
    const auto fnKnobs = [](const auto& in) {
        using T = typename std::decay_t<decltype(in)>::Scalar;
        julia::JuliaParams<T> params;
        params.iterations = 30;
        params.marchSteps = 24;
        params.precis = T(0.005f);
        params.normalOffset = T(0.002f);
        return julia::JuliaDistance(in.a, in.b, params);
    };
    EXPECT_GT(checkLanes("JuliaDistance(params)", rays, fnKnobs, flat, isHit), 0);
}

TEST(LanesFractals, JuliaRaycastJdistAndNormalMatchScalarPerLane) {
    // q-space rays straight into raycast, with a per-lane cut plane deltaT.
    std::vector<Input<float>> rays = raysAtBall(31, 160, glm::vec3(0, -0.5f, 0), 1.3f);
    const auto flatAny = [](Bits& b, const auto& r, int i) { put(b, r, i); };
    const auto fn = [](const auto& in) {
        using T = typename std::decay_t<decltype(in)>::Scalar;
        return julia::raycast(in.a, in.b, julia::kc<T>(), T(in.s) - T(0.5f));
    };
    const auto isHit = [](const glm::vec2& r) { return r.x >= 0; };
    EXPECT_GT(checkLanes("julia::raycast", rays, fn, flatAny, isHit), 0);
    const auto fnSphere = [](const auto& in) {
        using T = typename std::decay_t<decltype(in)>::Scalar;
        return julia::iSphere(in.a, in.b, T(1.2f));
    };
    EXPECT_GT(checkLanes("julia::iSphere", rays, fnSphere, flatAny, isHit), 0);

    std::vector<Input<float>> pts = positions(32, 320, 1.3f, 0.9f);
    pts[3].a = glm::vec3(0);  // d = +inf, n = 22 (H8)
    for (const int iMax : {1, 10, 200}) {
        const auto jd = [iMax](const auto& in) {
            using T = typename std::decay_t<decltype(in)>::Scalar;
            return julia::jdist(in.a, julia::kc<T>(), iMax);
        };
        // Groups mix lanes that leave the loop early and late.
        const auto escaped = [iMax](const glm::vec2& r) { return r.y < float(std::min(iMax, 4)); };
        const int mixed = checkLanes("julia::jdist", pts, jd, flatAny, escaped);
        if (iMax > 1) {
            EXPECT_GT(mixed, 0) << "iMax " << iMax;
        }
    }
    const auto normal = [](const auto& in) { return julia::calcNormal(in.a); };
    checkLanes("julia::calcNormal", pts, normal, flatAny, kNoHit);
}

TEST(LanesFractals, JuliaQueuesGiveEachRayItsScalarResult) {
    // raycastQueue and JuliaDistanceQueue refill their lanes from a queue of up to 16 rays: every ray's result is
    // bit for bit the one-ray result, for every queue length, with rays ruled out by the cut planes or the sphere
    // (raysAtBall's spread puts some outside), rays that run out of march steps, and queues shorter than the lanes.
    std::vector<Input<float>> rays = raysAtBall(33, 160, glm::vec3(0, -0.5f, 0), 1.3f);
    const std::vector<Input<float>> local = juliaRays(34, 96);
    int ruledOut = 0, hits = 0, queues = 0;
    for (const int maxSteps : {julia::kMarchSteps, 24, 0}) {
        size_t first = 0;
        for (int count = 1; first < rays.size(); count = count % julia::kMaxRaycastQueue + 1) {  // queues of 1..16
            const int n = int(std::min<size_t>(size_t(count), rays.size() - first));
            std::vector<glm::vec3> ro(static_cast<size_t>(n)), rd(static_cast<size_t>(n));
            std::vector<glm::vec2> got(static_cast<size_t>(n));
            const float deltaT = float(first % 3) * 0.25f - 0.25f;
            for (int k = 0; k < n; ++k) {
                ro[size_t(k)] = rays[first + size_t(k)].a;
                rd[size_t(k)] = rays[first + size_t(k)].b;
            }
            julia::raycastQueue<L>(ro.data(), rd.data(), n, got.data(), julia::kc<L>(), deltaT, julia::kIterations,
                                   maxSteps);
            ++queues;
            for (int k = 0; k < n; ++k) {
                const glm::vec2 want = julia::raycast(ro[size_t(k)], rd[size_t(k)], julia::kc<float>(), deltaT,
                                                      julia::kIterations, maxSteps);
                Bits a, b;
                put(a, got[size_t(k)], 0);
                put(b, want, 0);
                EXPECT_EQ(a, b) << "raycastQueue: ray " << first + size_t(k) << " of a queue of " << n
                                << ", maxSteps " << maxSteps;
                ruledOut += want.x == -2.0f ? 1 : 0;
                hits += want.x >= 0.0f ? 1 : 0;
            }
            first += size_t(n);
        }
    }
    EXPECT_GT(ruledOut, 0);
    EXPECT_GT(hits, 0);
    for (const int marchSteps : {julia::kMarchSteps, 24}) {
        julia::JuliaParams<float> params;
        params.marchSteps = marchSteps;
        for (size_t first = 0; first < local.size(); first += julia::kMaxRaycastQueue) {
            const int n = int(std::min<size_t>(julia::kMaxRaycastQueue, local.size() - first));
            std::vector<glm::vec3> ro(static_cast<size_t>(n)), rd(static_cast<size_t>(n));
            std::vector<julia::JuliaHit<float>> got(static_cast<size_t>(n));
            for (int k = 0; k < n; ++k) {
                ro[size_t(k)] = local[first + size_t(k)].a;
                rd[size_t(k)] = local[first + size_t(k)].b;
            }
            julia::JuliaDistanceQueue<L>(ro.data(), rd.data(), n, got.data(), params);
            for (int k = 0; k < n; ++k) {
                const julia::JuliaHit<float> want = julia::JuliaDistance(ro[size_t(k)], rd[size_t(k)], params);
                Bits a, b;
                put(a, got[size_t(k)].hit, 0);
                put(a, got[size_t(k)].normal, 0);
                put(a, got[size_t(k)].resT, 0);
                put(b, want.hit, 0);
                put(b, want.normal, 0);
                put(b, want.resT, 0);
                EXPECT_EQ(a, b) << "JuliaDistanceQueue: ray " << first + size_t(k) << ", marchSteps " << marchSteps;
            }
        }
    }
    EXPECT_GT(queues, 20);
}

// ---- Pac-man ------------------------------------------------------------------------------------------------------
TEST(LanesFractals, PacmanSdfAndHitColorMatchScalarPerLane) {
    std::vector<Input<float>> pts = positions(41, 480, 0.8f, 0.5f);
    const auto flatAny = [](Bits& b, const auto& r, int i) { put(b, r, i); };
    const auto sdf = [](const auto& in) { return pacman::pacMan(in.a, in.s); };  // a mouth per lane
    EXPECT_GT(checkLanes("pacMan", pts, sdf, flatAny, [](float d) { return d < 0; }), 0);
    const auto sdfDefault = [](const auto& in) { return pacman::pacMan(in.a); };
    checkLanes("pacMan(t = 0.5)", pts, sdfDefault, flatAny, kNoHit);
    // The normal is the radial direction (white head) for some lanes, random (black) or NaN for others.
    for (size_t k = 0; k < pts.size(); ++k) {
        if (k % 3 == 1) pts[k].b = normalized(pts[k].a);
        if (k % 11 == 5) pts[k].b.x = std::numeric_limits<float>::quiet_NaN();
    }
    const auto color = [](const auto& in) { return pacman::PacmanHitColor(in.b, in.a); };
    EXPECT_GT(checkLanes("PacmanHitColor", pts, color, flatAny, [](const glm::vec4& c) { return c.x == 1; }), 0);
}

// ---- D3D12: fractal pyramid and the SignedDistance switch ---------------------------------------------------------
TEST(LanesFractals, FractalPyramidAndSignedDistanceSwitchMatchScalarPerLane) {
    const std::vector<Input<float>> pts = positions(51, 480, 1.1f, 0.9f);
    const auto flatAny = [](Bits& b, const auto& r, int i) { put(b, r, i); };
    const auto inside = [](float d) { return d < 0; };
    for (const int iterations : {0, 1, 4, 6}) {
        const auto fn = [iterations](const auto& in) {
            using T = typename std::decay_t<decltype(in)>::Scalar;
            return d3d12::sdFractalPyramid(in.a + vec3<T>(T(0), T(1), T(0)), vec3<T>(T(0.894), T(0.447), T(2.0)),
                                           T(2) + T(in.s), iterations);
        };
        checkLanes("sdFractalPyramid", pts, fn, flatAny, inside);
    }
    // Every primitive, and an unknown one (0).
    for (std::uint32_t k = 0; k <= 7; ++k) {
        const auto primitive = d3d12::SignedDistancePrimitive(k);
        const auto fn = [primitive](const auto& in) {
            return d3d12::GetDistanceFromSignedDistancePrimitive(in.a, primitive);
        };
        const int mixed = checkLanes("GetDistanceFromSignedDistancePrimitive", pts, fn, flatAny, inside);
        if (k < 7) {
            EXPECT_GT(mixed, 0) << "primitive " << k;
        }
    }
}

// The lanes pick the pyramid's nearest vertex by a tree of minimums, the scalar code by four ifs in order: the same
// vertex where distances tie (at (0, 0.5, 0) the apex ties with the four base vertices; on the axis and the base's
// diagonals base vertices tie), where a position is NaN, infinite or huge, and with denormal distances (flushed, as
// the float ports run). Each lane's distance is bit for bit its scalar result.
TEST(LanesFractals, FractalPyramidPicksTheIfsVertexOnTiesNaNAndInfinity) {
    hlsl::ScopedFlushDenormals ftz;
    const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
    const float tiny = std::numeric_limits<float>::denorm_min();
    const std::vector<glm::vec3> points = {
        {0, 0, 0},           {0, 1, 0},       {0, -3, 0},          {0.5f, 0, 0.5f},   {-0.5f, 0, 0.5f},
        {0.5f, 0, -0.5f},    {0, 0.2f, 0.7f}, {0.7f, 0.2f, 0},     {nan, 0, 0},       {0, nan, 1},
        {inf, 0, 0},         {-inf, inf, 0},  {3e19f, 0, 3e19f},   {0, 3e19f, 0},     {tiny, 0, tiny},
        {-tiny, tiny, tiny}, {1e-20f, 0, 0},  {0, 0, -1e-20f},     {0.25f, 0.5f, 0},  {0, 0.5f, 0.25f},
        {0, 0.5f, 0},
    };
    const vec3<float> h(0.894f, 0.447f, 2.0f);
    for (size_t first = 0; first < points.size(); ++first) {
        vec3<L> p;
        for (int i = 0; i < kTestLanes; ++i) setLane(p, i, points[(first + size_t(i)) % points.size()]);
        const L lanes = d3d12::sdFractalPyramid(p, vec3<L>(h), L(2), 4);
        for (int i = 0; i < kTestLanes; ++i) {
            const glm::vec3 q = points[(first + size_t(i)) % points.size()];
            const float scalar = d3d12::sdFractalPyramid(vec3<float>(q), h, 2.0f, 4);
            EXPECT_EQ(std::bit_cast<std::uint32_t>(lane(lanes, i)), std::bit_cast<std::uint32_t>(scalar))
                << "position (" << q.x << ", " << q.y << ", " << q.z << ")";
        }
    }
}

// ---- PerturbedFloat: every converted function still instantiates (masks are bool), and without a perturbed::Scope
// it computes exactly what float does.
TEST(LanesFractals, PerturbedFloatStillInstantiatesAndEqualsFloatWithoutScope) {
    const auto pf = [](const glm::vec3& v) { return vec3<P>(P(v.x), P(v.y), P(v.z)); };
    const auto bits = [](float x) { return std::bit_cast<std::uint32_t>(x); };
    for (const Input<float>& in : raysAtBall(61, 24, glm::vec3(0), 1.25f)) {
        const mandelbulb::MandelbulbHit<P> m = mandelbulb::MandelbulbDistance(pf(in.a), pf(in.b), 30);
        const mandelbulb::MandelbulbHit<float> mf = mandelbulb::MandelbulbDistance(in.a, in.b, 30);
        EXPECT_EQ(m.hit, mf.hit);
        EXPECT_EQ(bits(m.thit.value()), bits(mf.thit));
        EXPECT_EQ(bits(m.normal.x.value()), bits(mf.normal.x));
        EXPECT_EQ(bits(m.color.w.value()), bits(mf.color.w));
        EXPECT_EQ(bits(pacman::pacMan(pf(in.a), P(in.s)).value()), bits(pacman::pacMan(in.a, in.s)));
        EXPECT_EQ(bits(pacman::PacmanHitColor(pf(in.b), pf(in.a)).x.value()),
                  bits(pacman::PacmanHitColor(in.b, in.a).x));
        const vec3<P> h(P(0.894), P(0.447), P(2.0));
        EXPECT_EQ(bits(d3d12::sdFractalPyramid(pf(in.a), h).value()),
                  bits(d3d12::sdFractalPyramid(in.a, glm::vec3(0.894f, 0.447f, 2.0f))));
        for (std::uint32_t k = 0; k < 7; ++k) {
            EXPECT_EQ(bits(d3d12::GetDistanceFromSignedDistancePrimitive(pf(in.a), d3d12::SignedDistancePrimitive(k))
                               .value()),
                      bits(d3d12::GetDistanceFromSignedDistancePrimitive(in.a, d3d12::SignedDistancePrimitive(k))));
        }
    }
    for (const Input<float>& in : juliaRays(62, 12)) {
        julia::JuliaParams<P> params;
        params.marchSteps = 64;
        julia::JuliaParams<float> paramsF;
        paramsF.marchSteps = 64;
        const julia::JuliaHit<P> j = julia::JuliaDistance(pf(in.a), pf(in.b), params);
        const julia::JuliaHit<float> jf = julia::JuliaDistance(in.a, in.b, paramsF);
        EXPECT_EQ(j.hit, jf.hit);
        EXPECT_EQ(bits(j.resT.x.value()), bits(jf.resT.x));
        EXPECT_EQ(bits(j.resT.y.value()), bits(jf.resT.y));
        EXPECT_EQ(bits(j.normal.z.value()), bits(jf.normal.z));
    }
}

}  // namespace
}  // namespace refray::procedural::math
