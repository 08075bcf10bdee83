// Readers for what every part of a scene file holds: names, numbers, vectors and flag sets.
#include <cmath>

#include "core/strings.h"
#include "scenes/loader/parse_context.h"

namespace refray::scenes::loader {

uint32_t resolveName(const Value& value, const std::vector<std::string>& names, const std::string& kind) {
    const std::string& name = value.asString();
    for (size_t i = 0; i < names.size(); ++i)
        if (names[i] == name) return uint32_t(i);
    value.fail("unknown " + kind + " " + inQuotes(name) + didYouMean(name, names) +
               (names.empty() ? "; none are defined" : "; defined: " + joined(names)));
}

std::string nonEmptyName(const Value& value, const std::string& what) {
    const std::string& s = value.asString();
    if (s.empty()) value.fail(what + " must not be empty");
    return s;
}

glm::dvec3 doubleVector3(const Value& value, const std::string& what) {
    const auto& a = value.asArray();
    if (a.size() != 3) value.fail(what + " needs 3 numbers, got " + std::to_string(a.size()));
    glm::dvec3 v;
    for (int i = 0; i < 3; ++i) {
        v[i] = a[size_t(i)].asNumber();
        if (!std::isfinite(v[i])) a[size_t(i)].fail(what + " must be finite");
    }
    return v;
}

double finiteNumber(const Value& value, const std::string& what) {
    const double d = value.asNumber();
    if (!std::isfinite(d)) value.fail(what + " must be finite");
    return d;
}

uint32_t flagSet(const Value& value, const std::vector<std::pair<std::string, uint32_t>>& known, const std::string& what) {
    std::vector<std::string> names;
    for (const auto& k : known) names.push_back(k.first);
    uint32_t flags = 0;
    for (const Value& v : value.asArray()) flags |= known[resolveName(v, names, what)].second;
    return flags;
}

}  // namespace refray::scenes::loader
