#include "emulator/validation.h"

#include <algorithm>
#include <cstdio>

#include "core/strings.h"

namespace refray::dxr {

std::string Diagnostic::format() const {
    std::ostringstream s;
    s << (severity == Severity::Error ? "error " : severity == Severity::Note ? "note " : "warning ") << ruleId << ": "
      << message;
    if (site) {
        s << " [launch (" << site->launchIndex.x << "," << site->launchIndex.y << "," << site->launchIndex.z
          << "), depth " << site->depth << ", " << toString(site->stage);
        if (!site->exportName.empty()) s << " '" << site->exportName << "'";
        s << "]";
    }
    if (!values.empty()) {
        s << ";";
        for (size_t i = 0; i < values.size(); ++i) {
            s << (i ? ", " : " ") << values[i].name << " = " << values[i].value;
            if (!values[i].limit.empty()) s << " (limit " << values[i].limit << ")";
        }
    }
    if (count > 1) s << " (" << count << " occurrences)";
    return s.str();
}

DxrError::DxrError(Diagnostic diagnostic) : Error(diagnostic.format()), diagnostic_(std::move(diagnostic)) {}

void DiagnosticLog::add(const Diagnostic& d, uint64_t orderKey) {
    auto key = std::make_pair(d.ruleId, d.message);
    auto it = records_.find(key);
    if (it == records_.end()) {
        records_.emplace(std::move(key), Record{d, orderKey});
        return;
    }
    Record& r = it->second;
    const uint64_t total = r.diagnostic.count + d.count;
    if (orderKey < r.orderKey) {
        r.diagnostic = d;
        r.orderKey = orderKey;
    }
    r.diagnostic.count = total;
}

void DiagnosticLog::merge(const DiagnosticLog& other) {
    for (const auto& [key, record] : other.records_) add(record.diagnostic, record.orderKey);
}

std::vector<Diagnostic> DiagnosticLog::diagnostics() const {
    std::vector<const Record*> sorted;
    for (const auto& [key, record] : records_) sorted.push_back(&record);
    std::stable_sort(sorted.begin(), sorted.end(), [](const Record* a, const Record* b) {
        if (a->orderKey != b->orderKey) return a->orderKey < b->orderKey;
        return a->diagnostic.ruleId < b->diagnostic.ruleId;
    });
    std::vector<Diagnostic> out;
    for (const Record* r : sorted) out.push_back(r->diagnostic);
    return out;
}

std::vector<Diagnostic> DiagnosticLog::errors() const {
    std::vector<Diagnostic> out;
    for (auto& d : diagnostics())
        if (d.severity == Severity::Error) out.push_back(d);
    return out;
}

std::vector<Diagnostic> DiagnosticLog::warnings() const {
    std::vector<Diagnostic> out;
    for (auto& d : diagnostics())
        if (d.severity == Severity::Warning) out.push_back(d);
    return out;
}

std::vector<Diagnostic> DiagnosticLog::notes() const {
    std::vector<Diagnostic> out;
    for (auto& d : diagnostics())
        if (d.severity == Severity::Note) out.push_back(d);
    return out;
}

std::optional<Diagnostic> DiagnosticLog::find(const std::string& ruleId) const {
    for (auto& d : diagnostics())
        if (d.ruleId == ruleId) return d;
    return std::nullopt;
}

DiagnosticBuilder::DiagnosticBuilder(std::string ruleId, std::string message, Severity severity) {
    diagnostic_.ruleId = std::move(ruleId);
    diagnostic_.message = std::move(message);
    diagnostic_.severity = severity;
}

DiagnosticBuilder& DiagnosticBuilder::hex(std::string name, uint64_t v, std::string limit) {
    diagnostic_.values.push_back({std::move(name), hexText(v), std::move(limit)});
    return *this;
}

}  // namespace refray::dxr
