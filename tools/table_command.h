// `refray table SCENE`: the shader tables of a scene as the GPU sees them (records, identifiers, decoded local
// root arguments), the instances and geometries that feed the indexing rule, and a static check of
// I = R + M*G + C for every instance x geometry x ray type (inspect/table_view.h), as text or JSON.
//
// Wiring into the main program (tools/refray.cpp):
//     refray::tools::TableCommandOptions tableOptions;
//     CLI::App* table = refray::tools::addTableCommand(app, tableOptions);
//     ...after app.parse(argc, argv):
//     if (*table) return refray::tools::runTable(tableOptions);
#pragma once

#include <string>

#include <CLI/CLI.hpp>

#include "inspect/table_view.h"

namespace refray::tools {

struct TableCommandOptions {
    std::string scene;
    std::string precision = "float";
    bool json = false;
    bool check = false;
    bool warningsAsErrors = false;  // --warnings-as-errors
};

// Adds the `table` subcommand to `app`; app.parse() fills `options`, which must outlive the parse.
CLI::App* addTableCommand(CLI::App& app, TableCommandOptions& options);

// Prints the view to stdout. Exit status: 0, or 1 with --check when there is an error-level finding;
// 2 when the scene cannot be loaded or built (the message goes to stderr). Throws nothing.
int runTable(const TableCommandOptions& options);

// The text and JSON forms of a view (what runTable prints).
std::string formatTableText(const scenes::TableView& view);
std::string formatTableJson(const scenes::TableView& view);

}  // namespace refray::tools
