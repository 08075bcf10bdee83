// Errors and warnings raised while a dispatch runs: each is located at its launch index, depth, stage and
// export, then thrown or recorded as DispatchOptions::onError says (GEN-1). Internal to the emulator.
#pragma once

#include <cstdint>
#include <string>

#include "emulator/detail/invocation.h"
#include "emulator/validation.h"

namespace refray::dxr::detail {

struct ThreadState;
struct NoteTally;

// Where a diagnostic arises: the stage, export and depth of the invocation that raises it.
struct Site {
    ShaderStage stage;
    const std::string* exportName;
    uint32_t depth;
};

inline const std::string kNoExport;

inline Site siteOf(const Invocation& inv) {
    return {inv.stage, inv.shader ? &inv.shader->name : &kNoExport, inv.depth};
}

// `d` with its site: the thread's launch index and `site`.
Diagnostic locate(const ThreadState& ts, Diagnostic d, const Site& site);

// An error at `site`. OnError::Stop: throws. Continue: records it and returns, and the
// caller applies the fallback its rule documents.
void raise(ThreadState& ts, const Site& site, const Diagnostic& d);

void warn(ThreadState& ts, const Site& site, const Diagnostic& d);

// A note counted in `tally` (NoteTally): logged in full only when it is the thread's first or comes from a smaller
// launch index than the one logged, so repeating it costs a counter. `make` builds the diagnostic.
template <class Make>
void note(ThreadState& ts, const Site& site, NoteTally& tally, Make make);

// note's repeat: true, and counted, when `tally` already holds the note of this or a smaller launch index. A caller
// that asks first need not build the site of a note that only counts.
bool countRepeatedNote(const ThreadState& ts, NoteTally& tally);

// Adds the counts `note` kept back to the thread's log; called once when the dispatch ends.
void foldNotes(ThreadState& ts);

// Stops the invocation with a DxrError carrying `rule`, the stage and the launch site: misuse of the shader API
// always stops, there is no fallback.
[[noreturn]] void stageError(Invocation& inv, const char* rule, const std::string& message);

}  // namespace refray::dxr::detail

#include "emulator/detail/thread_state.h"

inline bool refray::dxr::detail::countRepeatedNote(const ThreadState& ts, NoteTally& tally) {
    if (!tally.logged || ts.linearIndex < tally.orderKey) return false;
    ++tally.more;
    return true;
}

template <class Make>
void refray::dxr::detail::note(ThreadState& ts, const Site& site, NoteTally& tally, Make make) {
    if (countRepeatedNote(ts, tally)) return;
    tally.logged = true;
    tally.orderKey = ts.linearIndex;
    tally.first = locate(ts, make(), site);
    ts.log.add(tally.first, ts.linearIndex);
}
