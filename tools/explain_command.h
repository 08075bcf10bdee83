// `refray explain SCENE --pixel X,Y`: the ray tree of one pixel (inspect/explain.h), as text or JSON.
// docs/tutorial-indexing.md walks through its output.
#pragma once

#include <optional>
#include <string>

#include <CLI/CLI.hpp>

namespace refray::tools {

struct ExplainCommandOptions {
    std::string scene;
    std::string pixel;
    std::string camera;
    std::string size;  // empty: the scene's imageSize
    std::optional<float> time;
    std::string precision = "float";
    std::string order = "ordered";
    uint64_t seed = 0;
    bool json = false;
    bool warningsAsErrors = false;  // --warnings-as-errors
    std::string output;  // empty: stdout
    std::string html;    // write the interactive page here (every pixel; --pixel then only preselects one)
};

CLI::App* addExplainCommand(CLI::App& app, ExplainCommandOptions& options);
// Prints (or writes) the explanation; with --html writes a self-contained page where hovering a pixel of the
// render shows its ray tree (docs/tutorial-indexing.md). Returns 0, or 1 when the pixel ended in a DXR error (the explanation
// shows it); bad options and unreadable scenes throw refray::Error (exit 2 in main).
int runExplain(const ExplainCommandOptions& options);

}  // namespace refray::tools
