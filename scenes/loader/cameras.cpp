// "cameras", and the rest of what a frame is rendered with: "light", "time" and "effects".
#include <algorithm>
#include <cmath>
#include <sstream>

#include "core/error.h"
#include "core/strings.h"
#include "scenes/camera_models.h"
#include "scenes/loader/parse_context.h"
#include "procedural/sample_layout.h"

namespace refray::scenes::loader {

namespace {

std::string pointText(const glm::dvec3& p) {
    std::ostringstream s;
    s << p.x << ", " << p.y << ", " << p.z;
    return s.str();
}

// The camera rays the shaders make (GenerateCameraRay: a screen position through projectionToWorld, divided by w,
// minus the eye), in float as on a GPU, at the screen's corners and centre: a camera whose rays overflow is refused at
// load instead of stopping the render with a RAY-5 error that names no file.
void checkCameraRays(const CameraDesc& c, const procedural::Float4x4& projectionToWorld) {
    const glm::vec3 eye(c.eye);
    REFRAY_CHECK(std::isfinite(eye.x) && std::isfinite(eye.y) && std::isfinite(eye.z),
                 "camera " << inQuotes(c.name) << ": its rays overflow float: the eye (" << pointText(c.eye)
                           << ", after rotateYDegrees) is beyond float's range (+-3.4e38), so the shaders' ray origin "
                              "would be infinite");
    const auto& m = projectionToWorld.m;
    const glm::vec2 screens[] = {{-1, -1}, {1, -1}, {-1, 1}, {1, 1}, {0, 0}};
    for (const glm::vec2 screen : screens) {
        const float in[4] = {screen.x, screen.y, 0.0f, 1.0f};
        float world[4] = {0, 0, 0, 0};
        for (int j = 0; j < 4; ++j)
            for (int i = 0; i < 4; ++i) world[j] += in[i] * m[size_t(i)][size_t(j)];
        const glm::vec3 direction = glm::vec3(world[0], world[1], world[2]) / world[3] - eye;
        const float length = glm::length(direction);
        REFRAY_CHECK(std::isfinite(length) && length > 0.0f && std::isfinite(direction.x / length) &&
                         std::isfinite(direction.y / length) && std::isfinite(direction.z / length),
                     "camera " << inQuotes(c.name) << ": its rays overflow float (the ray through screen position ("
                               << screen.x << ", " << screen.y << ") has direction (" << direction.x << ", "
                               << direction.y << ", " << direction.z << ")); eye (" << pointText(c.eye) << "), target ("
                               << pointText(c.target) << "), near " << c.nearZ << ", far " << c.farZ
                               << ": bring them within float's range");
    }
}

}  // namespace

void parseCameras(ParseContext& ctx, const Value& value, const Value* defaultCamera) {
    std::vector<std::string> names;
    for (const Value& v : value.asArray()) {
        ObjectReader r(v, "a camera");
        CameraDesc c;
        c.name = nonEmptyName(r.required("name"), "a camera name");
        r.setWhat("camera " + inQuotes(c.name));
        if (std::find(names.begin(), names.end(), c.name) != names.end()) v.fail("two cameras are named " + inQuotes(c.name));
        const uint32_t model = resolveName(r.required("model"), {"miniengine", "directxmath-lh"}, "camera model");
        c.model = model == 0 ? CameraModel::MiniEngine : CameraModel::DirectXMathLH;
        c.eye = doubleVector3(r.required("eye"), "eye");
        const Value& target = r.required("target");
        c.target = doubleVector3(target, "target");
        // Checked first, so that neither 'up' nor 'upFromRight' is blamed for a view direction that does not exist.
        if (c.target == c.eye)
            target.fail("camera " + inQuotes(c.name) + ": eye and target are the same point (" + pointText(c.eye) +
                        "), so the camera has no view direction");
        const Value* up = r.optional("up");
        const Value* upFromRight = r.optional("upFromRight");
        if (up && upFromRight) upFromRight->fail("give 'up' or 'upFromRight', not both");
        if (up) {
            c.up = doubleVector3(*up, "up");
        } else if (upFromRight) {
            // up = normalize(cross(normalize(target - eye), right)), as both samples' hosts compute it.
            const glm::dvec3 right = doubleVector3(*upFromRight, "upFromRight");
            const glm::dvec3 forward = glm::normalize(c.target - c.eye);
            const glm::dvec3 u = glm::cross(forward, right);
            if (!(glm::length(u) > 0.0)) upFromRight->fail("upFromRight is parallel to the view direction");
            c.up = glm::normalize(u);
        } else {
            v.fail("camera " + inQuotes(c.name) + " needs 'up' or 'upFromRight'");
        }
        if (const Value* rot = r.optional("rotateYDegrees")) {
            // XMMatrixRotationY applied to eye and up (row vectors): x' = x·cos + z·sin, z' = -x·sin + z·cos.
            const double a = finiteNumber(*rot, "rotateYDegrees") * 3.14159265358979323846 / 180.0;
            auto rotate = [a](glm::dvec3 p) {
                return glm::dvec3(p.x * std::cos(a) + p.z * std::sin(a), p.y, -p.x * std::sin(a) + p.z * std::cos(a));
            };
            c.eye = rotate(c.eye);
            c.up = rotate(c.up);
            c.target = rotate(c.target);
        }
        c.fovYRadians = finiteNumber(r.required("fovYDegrees"), "fovYDegrees") * 3.14159265358979323846 / 180.0;
        c.nearZ = finiteNumber(r.required("near"), "near");
        c.farZ = finiteNumber(r.required("far"), "far");
        r.finish();
        try {
            // Validates the camera here, where its file position is known: the matrix, then the rays.
            checkCameraRays(c, projectionToWorld(c, 16, 9));
        } catch (const Error& e) {
            v.fail(e.what());
        }
        names.push_back(c.name);
        ctx.scene.cameras.push_back(c);
    }
    if (ctx.scene.cameras.empty()) value.fail("a scene needs at least one camera");
    if (defaultCamera) ctx.scene.defaultCamera = resolveName(*defaultCamera, names, "camera");
}

void parseLight(ParseContext& ctx, const Value& value) {
    ObjectReader r(value, "light");
    ctx.scene.light.position = floatVector<4>(r.required("position"), "position");
    ctx.scene.light.ambientColor = floatVector<4>(r.required("ambientColor"), "ambientColor");
    ctx.scene.light.diffuseColor = floatVector<4>(r.required("diffuseColor"), "diffuseColor");
    r.finish();
}

void parseTime(ParseContext& ctx, const Value& value) {
    ObjectReader r(value, "time");
    if (const Value* d = r.optional("default")) {
        ctx.scene.defaultTime = d->asFloat();
        ctx.scene.defaultTimeText = d->numberText();
        if (ctx.scene.defaultTime < 0.0f) d->fail("time must not be negative (the samples' time only grows)");
    }
    if (const Value* c = r.optional("canonical"))
        for (const Value& t : c->asArray()) {
            ctx.scene.canonicalTimes.push_back(t.asFloat());
            if (ctx.scene.canonicalTimes.back() < 0.0f) t.fail("time must not be negative");
        }
    r.finish();
}

void parseEffects(ParseContext& ctx, const Value& value) {
    ObjectReader r(value, "effects");
    ctx.scene.effects.present = true;
    ctx.scene.effects.where = value.location();
    if (const Value* v = r.optional("shadows")) {
        if (!v->isBool()) v->fail("'shadows' in effects is true or false, got " + std::string(v->kindName()));
        ctx.scene.effects.shadows = v->asBool();
    }
    if (const Value* v = r.optional("reflectionDepth")) {
        if (!v->isNumber())
            v->fail("'reflectionDepth' in effects is an integer 1..31, got " + std::string(v->kindName()));
        const uint32_t depth = v->asUint32();
        if (depth < 1 || depth > 31)
            v->fail("reflectionDepth is the shaders' MAX_RAY_RECURSION_DEPTH, 1..31 (1: camera rays only), got " +
                    std::to_string(depth));
        ctx.scene.effects.reflectionDepth = depth;
    }
    r.finish();
}

}  // namespace refray::scenes::loader
