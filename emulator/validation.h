// Diagnostics for what DXR leaves undefined (GEN-1, GEN-2, GEN-4).
//
// Every [UB] case the emulator observes becomes a Diagnostic: the rule id from
// dxr-semantics.md, where it happened (launch index, depth, stage, export) and each
// offending value beside the limit it broke. Errors stop the dispatch by default
// (DxrError); warnings never change a result and are only collected.
#pragma once

#include <cstdint>
#include <map>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "core/error.h"
#include "core/math.h"
#include "emulator/types.h"

namespace refray::dxr {

// Note: a use DXR defines that another API leaves undefined (RayQuery, dxr-semantics.md 18e); never a warning.
enum class Severity : uint8_t { Warning, Error, Note };

struct DiagnosticValue {
    std::string name;
    std::string value;
    std::string limit;  // empty when the value has no limit of its own
};

// Where a diagnostic arose inside a dispatch; absent for build-time diagnostics.
struct DiagnosticSite {
    uvec3 launchIndex{0u};
    uint32_t depth = 0;
    ShaderStage stage = ShaderStage::RayGeneration;
    std::string exportName;
};

struct Diagnostic {
    std::string ruleId;  // e.g. "IDX-11"
    Severity severity = Severity::Error;
    std::string message;  // what happened, with the values written out
    std::vector<DiagnosticValue> values;
    std::optional<DiagnosticSite> site;  // first occurrence
    uint64_t count = 1;                  // occurrences folded into this record (GEN-2)

    // "error IDX-11: ... [launch (3,4,0), depth 1, closesthit 'CH']; R = 1, ..."
    std::string format() const;
};

// The exception a stopped dispatch or a refused build throws.
class DxrError : public Error {
public:
    explicit DxrError(Diagnostic diagnostic);
    const Diagnostic& diagnostic() const { return diagnostic_; }

private:
    Diagnostic diagnostic_;
};

// A de-duplicated, deterministic set of diagnostics (GEN-2). Records are keyed by
// (rule, message); the first occurrence is the one with the smallest ordering key
// (the linear launch index during a dispatch), so thread scheduling cannot change it.
class DiagnosticLog {
public:
    void add(const Diagnostic& diagnostic, uint64_t orderKey = 0);
    void merge(const DiagnosticLog& other);
    // Sorted by first-occurrence order, then rule id.
    std::vector<Diagnostic> diagnostics() const;
    std::vector<Diagnostic> errors() const;
    std::vector<Diagnostic> warnings() const;
    std::vector<Diagnostic> notes() const;
    bool empty() const { return records_.empty(); }
    // Finds the first record with this rule id.
    std::optional<Diagnostic> find(const std::string& ruleId) const;

private:
    struct Record {
        Diagnostic diagnostic;
        uint64_t orderKey = 0;
    };
    std::map<std::pair<std::string, std::string>, Record> records_;
};

// Builds a Diagnostic in one expression:
//   throw DxrError(diag("IDX-11", "hit-group record past the table end").value("I", i).limit(...));
class DiagnosticBuilder {
public:
    DiagnosticBuilder(std::string ruleId, std::string message, Severity severity = Severity::Error);
    template <class T>
    DiagnosticBuilder& value(std::string name, const T& v, std::string limit = {}) {
        std::ostringstream s;
        s << v;
        diagnostic_.values.push_back({std::move(name), s.str(), std::move(limit)});
        return *this;
    }
    DiagnosticBuilder& hex(std::string name, uint64_t v, std::string limit = {});
    operator Diagnostic() const { return diagnostic_; }  // NOLINT: builder converts implicitly
    const Diagnostic& get() const { return diagnostic_; }

private:
    Diagnostic diagnostic_;
};

inline DiagnosticBuilder diag(std::string ruleId, std::string message) {
    return DiagnosticBuilder(std::move(ruleId), std::move(message), Severity::Error);
}
inline DiagnosticBuilder warning(std::string ruleId, std::string message) {
    return DiagnosticBuilder(std::move(ruleId), std::move(message), Severity::Warning);
}

// Thread-safe sink for build-time warnings (BLAS/TLAS/state-object builds).
class BuildLog {
public:
    void add(const Diagnostic& d) {
        std::lock_guard lock(mutex_);
        log_.add(d, sequence_++);
    }
    DiagnosticLog snapshot() const {
        std::lock_guard lock(mutex_);
        return log_;
    }

private:
    mutable std::mutex mutex_;
    DiagnosticLog log_;
    uint64_t sequence_ = 0;
};

}  // namespace refray::dxr
