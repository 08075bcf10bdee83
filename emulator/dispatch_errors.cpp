// Errors and warnings raised while a dispatch runs (detail/dispatch_errors.h).
#include "emulator/detail/dispatch_errors.h"

#include "emulator/detail/thread_state.h"

namespace refray::dxr::detail {

Diagnostic locate(const ThreadState& ts, Diagnostic d, const Site& site) {
    d.site = DiagnosticSite{ts.launchIndex, site.depth, site.stage, *site.exportName};
    return d;
}

void raise(ThreadState& ts, const Site& site, const Diagnostic& d) {
    Diagnostic located = locate(ts, d, site);
    if (ts.dispatch->options.onError == OnError::Stop) throw DxrError(std::move(located));
    ts.log.add(located, ts.linearIndex);
}

void warn(ThreadState& ts, const Site& site, const Diagnostic& d) { ts.log.add(locate(ts, d, site), ts.linearIndex); }

void foldNotes(ThreadState& ts) {
    for (NoteTally& tally : ts.queryNotes)
        if (tally.more) {
            Diagnostic d = tally.first;
            d.count = tally.more;
            ts.log.add(d, ~0ull);
            tally.more = 0;
        }
}

void stageError(Invocation& inv, const char* rule, const std::string& message) {
    throw DxrError(locate(*inv.thread, diag(rule, message).value("stage", toString(inv.stage)), siteOf(inv)));
}

}  // namespace refray::dxr::detail
