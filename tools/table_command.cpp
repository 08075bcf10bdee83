#include "tools/table_command.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <exception>
#include <memory>
#include <optional>

#include "core/error.h"
#include "core/json_writer.h"
#include "core/strings.h"
#include "emulator/types.h"
#include "scenes/scene.h"
#include "tools/cli_common.h"

namespace refray::tools {

using scenes::TableFinding;
using scenes::TableView;

namespace {

constexpr const char* kFooter = R"(The hit-group record a ray uses is (IDX-1)
  addr = HitGroupTable.StartAddress + HitGroupTable.StrideInBytes * I,   I = R + M*G + C
with R = RayContributionToHitGroupIndex and M = MultiplierForGeometryContributionToHitGroupIndex
(TraceRay arguments of the ray type, low 4 bits each), G = GeometryIndex (the geometry's position in its
BLAS) and C = InstanceContributionToHitGroupIndex (the instance's). The records are read from GPU memory
and their identifiers resolved through the state object; the reachability list computes I for every
instance x geometry x ray type and says what each record holds.

Findings carry the rule ids of dxr-semantics.md: errors are what a dispatch would stop on when a ray
reaches that record; warnings are legal but suspicious (or undefined only if a shader runs); notes say
what a reader may not expect (NULL records, records nothing reaches).

Exit status: 0; 1 with --check when there is an error; 2 when the scene cannot be loaded.)";

// Argument lines longer than this wrap (the detail indent not counted).
constexpr size_t kWrapColumn = 112;



std::string plural(uint64_t n, const char* one, const char* many) {
    std::string out = std::to_string(n);
    out += ' ';
    out += n == 1 ? one : many;
    return out;
}

// Rows of cells printed in aligned columns, each row optionally followed by free lines of detail.
class TextTable {
public:
    explicit TextTable(std::vector<std::string> header) { rows_.push_back({std::move(header), {}}); }
    void row(std::vector<std::string> cells) { rows_.push_back({std::move(cells), {}}); }
    void detail(std::string line) { rows_.back().details.push_back(std::move(line)); }

    void print(std::string& out) const {
        std::vector<size_t> widths;
        for (const Row& r : rows_)
            for (size_t c = 0; c < r.cells.size(); ++c) {
                if (widths.size() <= c) widths.push_back(0);
                widths[c] = std::max(widths[c], r.cells[c].size());
            }
        for (const Row& r : rows_) {
            std::string line = "  ";
            for (size_t c = 0; c < r.cells.size(); ++c) {
                line += r.cells[c];
                if (c + 1 < r.cells.size()) line.append(widths[c] - r.cells[c].size() + 2, ' ');
            }
            while (!line.empty() && line.back() == ' ') line.pop_back();
            out += line;
            out += '\n';
            for (const std::string& d : r.details) {
                size_t start = 0;
                while (start <= d.size()) {
                    const size_t end = std::min(d.find('\n', start), d.size());
                    out += "        ";
                    out.append(d, start, end - start);
                    out += '\n';
                    start = end + 1;
                }
            }
        }
    }

private:
    struct Row {
        std::vector<std::string> cells;
        std::vector<std::string> details;
    };
    std::vector<Row> rows_;
};

std::string argumentText(const scenes::RootArgumentView& a, const scenes::ShaderTableView& table) {
    std::string out = "[" + std::to_string(a.parameter) + "] " + a.kind;
    if (!a.shaderRegister.empty()) out += " " + a.shaderRegister;
    out += " @" + std::to_string(a.offset);
    if (!a.structName.empty()) out += " (" + a.structName + ")";
    out += ": ";
    if (!a.inTable) {
        out += "past the end of the table (SizeInBytes ";
        out += std::to_string(table.sizeInBytes);
        out += ')';
        return out;
    }
    if (a.kind == "root constants") {
        // Fields wrap at kWrapColumn; continuation lines are indented by 4.
        size_t lineStart = 0;
        for (size_t i = 0; i < a.fields.size(); ++i) {
            std::string field = a.fields[i].name + " = " + (a.fields[i].written ? a.fields[i].text() : "never written");
            if (i + 1 < a.fields.size()) field += ',';
            if (i > 0 && out.size() - lineStart + 1 + field.size() > kWrapColumn) {
                out += '\n';
                lineStart = out.size();
                out.append(4, ' ');
            } else if (i > 0) {
                out += ' ';
            }
            out += field;
        }
        return out;
    }
    if (!a.written) return out + "never written";
    if (a.kind == "descriptor table") return out + "handle " + hexText(a.address);
    out += hexText(a.address);
    if (a.buffer.empty()) return out + " (no buffer there)";
    out += " -> buffer " + inQuotes(a.buffer);
    if (a.bufferOffset) out += " + " + std::to_string(a.bufferOffset);
    return out;
}

std::string holdsText(const scenes::RecordView& r) {
    std::string out = r.describe();
    if (!r.hitGroupType.empty()) out += " (" + r.hitGroupType + ")";
    return out;
}

std::string shadersText(const scenes::RecordView& r) {
    std::string out;
    auto add = [&out](const char* stage, const std::string& name) {
        if (name.empty()) return;
        out += out.empty() ? "" : ", ";
        out += stage;
        out += ' ';
        out += name;
    };
    add("intersection", r.intersection);
    add("any-hit", r.anyHit);
    add("closest-hit", r.closestHit);
    return out.empty() ? "no shaders (an empty hit group)" : out;
}

void printTable(const scenes::ShaderTableView& t, std::string& out) {
    std::string title = t.name;
    title[0] = char(std::toupper(static_cast<unsigned char>(title[0])));
    out += title + ": StartAddress " + hexText(t.startAddress) + ", SizeInBytes " + std::to_string(t.sizeInBytes);
    if (t.key != "rayGeneration") {
        uint32_t largest = 0;
        for (const scenes::RecordView& r : t.records) largest = std::max(largest, r.layoutSize);
        out += ", StrideInBytes " + std::to_string(t.strideInBytes) + ", " + plural(t.recordCount, "record", "records");
        if (!t.records.empty()) out += " (largest record: " + std::to_string(largest) + " bytes)";
    }
    out += '\n';
    const bool hitGroups = t.key == "hitGroup";
    TextTable table({"record", "offset", "address", "holds", "local root signature"});
    for (const scenes::RecordView& r : t.records) {
        table.row({std::to_string(r.index), std::to_string(r.offset), hexText(r.address), holdsText(r),
                   r.localRootSignature.empty() ? "-" : r.localRootSignature + " (" + std::to_string(r.layoutSize) + " bytes)"});
        if (r.contents == scenes::RecordView::Contents::Unknown) table.detail("it is " + r.unknown);
        if (hitGroups && r.contents == scenes::RecordView::Contents::Export) table.detail(shadersText(r));
        if (t.strideInBytes != 0 && r.layoutSize > t.strideInBytes && r.index + 1 < t.recordCount)
            table.detail("its bytes " + std::to_string(t.strideInBytes) + ".." + std::to_string(r.layoutSize - 1) +
                         " are also the start of record " + std::to_string(r.index + 1) +
                         ": the stride is smaller than the record");
        for (const scenes::RootArgumentView& a : r.arguments) table.detail(argumentText(a, t));
        if (!r.origin.empty()) table.detail("from the scene file: " + r.origin);
    }
    table.print(out);
}

void writeRecord(json::Writer& w, const scenes::RecordView& r) {
    static const char* kContents[] = {"export", "null", "unknown", "unwritten"};
    w.beginObject();
    w.member("index", r.index).member("offset", r.offset).member("address", r.address);
    w.member("contents", kContents[size_t(r.contents)]);
    w.member("holds", r.describe());
    if (r.contents == scenes::RecordView::Contents::Export) {
        w.member("kind", r.kind).member("export", r.exportName);
        if (!r.hitGroupType.empty()) {
            w.member("hitGroupType", r.hitGroupType);
            for (const auto& [key, name] : {std::pair{"intersection", &r.intersection}, std::pair{"anyHit", &r.anyHit},
                                            std::pair{"closestHit", &r.closestHit}}) {
                w.key(key);
                if (name->empty()) w.null();
                else w.value(*name);
            }
        }
        w.key("payload");
        if (r.payload.empty()) w.null();
        else w.value(r.payload);
        w.key("localRootSignature");
        if (r.localRootSignature.empty()) w.null();
        else w.value(r.localRootSignature);
        w.member("layoutSize", r.layoutSize);
    }
    if (r.contents == scenes::RecordView::Contents::Unknown) w.member("unknown", r.unknown);
    w.key("arguments").beginArray();
    for (const scenes::RootArgumentView& a : r.arguments) {
        w.beginObject();
        w.member("parameter", a.parameter).member("kind", a.kind);
        if (!a.shaderRegister.empty()) w.member("register", a.shaderRegister);
        w.member("offset", a.offset).member("size", a.size).member("inTable", a.inTable).member("written", a.written);
        if (a.kind == "root constants") {
            w.key("struct");
            if (a.structName.empty()) w.null();
            else w.value(a.structName);
            w.key("fields").beginArray();
            for (const scenes::ConstantFieldView& f : a.fields) {
                w.beginObject(json::Writer::Layout::Inline);
                w.member("name", f.name).member("type", f.typeName()).member("text", f.text()).member("written", f.written);
                w.key("value").beginArray(json::Writer::Layout::Inline);
                for (uint32_t bits : f.dwords) {
                    switch (f.kind) {
                        case scenes::StructField::Kind::Float: {
                            float v = 0.0f;
                            std::memcpy(&v, &bits, 4);
                            if (std::isfinite(v)) w.value(v);
                            else w.value(std::to_string(v));  // JSON has no NaN or infinity
                            break;
                        }
                        case scenes::StructField::Kind::Int: w.value(int32_t(bits)); break;
                        case scenes::StructField::Kind::Uint: w.value(bits); break;
                    }
                }
                w.endArray();
                w.endObject();
            }
            w.endArray();
        } else if (a.inTable) {
            w.member("address", a.address);
            w.key("buffer");
            if (a.buffer.empty()) w.null();
            else w.value(a.buffer);
            w.member("bufferOffset", a.bufferOffset);
        }
        w.endObject();
    }
    w.endArray();
    if (!r.origin.empty()) w.member("origin", r.origin);
    w.endObject();
}

std::string numThreadsText(const uint32_t (&n)[3]) {
    return "numthreads(" + std::to_string(n[0]) + ", " + std::to_string(n[1]) + ", " + std::to_string(n[2]) + ")";
}

// The line a compute scene's header gets: what renders it, and that the tables are not read.
std::string computeDispatchText(const scenes::ComputeDispatchView& c) {
    return "Renders with a compute dispatch: Dispatch of compute shader " + inQuotes(c.shader) + ", " +
           numThreadsText(c.numThreads) +
           ", one thread per pixel (Device::dispatch). The ray-tracing pipeline and the shader tables below are built "
           "but not read by it: its rays are RayQuery objects.";
}

}  // namespace

std::string formatTableText(const TableView& v) {
    std::string out;
    out += "Scene " + inQuotes(v.scene) + ": shader library " + inQuotes(v.shaderLibrary) + ", " + v.precision +
           " shaders, state object " + inQuotes(v.stateObject) + "\n";
    out += "A ray's hit-group record: I = R + M*G + C, address = HitGroupTable.StartAddress + StrideInBytes * I (IDX-1)\n";
    if (!v.compute.shader.empty())
        out += computeDispatchText(v.compute) + "\n";
    out += '\n';
    if (!v.rayQueryOwners.empty()) {
        out += "RayQuery objects (RQ-2: the template ray flags each export declares; a query's flags are these | "
               "TraceRayInline's RayFlags, RQ-3). Inline queries read no shader table: the shader that owns one "
               "intersects its procedural candidates and commits its hits itself\n";
        TextTable owners({"export", "stage", "RayQuery objects", "in the scene"});
        for (const scenes::RayQueryOwnerView& o : v.rayQueryOwners) {
            std::string runs;
            if (o.exportName == v.compute.shader) runs = "the scene's compute dispatch, " + numThreadsText(o.numThreads);
            for (const std::string& g : o.hitGroups) runs += (runs.empty() ? "hit group " : ", ") + inQuotes(g);
            if (!v.compute.shader.empty() && !o.hitGroups.empty())
                runs += " (in the pipeline; the compute dispatch runs no hit group)";
            if (runs.empty()) runs = "-";
            std::string declarations;
            for (const std::string& d : o.declarations()) declarations += (declarations.empty() ? "" : ", ") + d;
            owners.row({o.exportName, o.stage, declarations, runs});
        }
        owners.print(out);
        out += '\n';
    }

    out += "Ray types (R, M, miss index and InstanceInclusionMask are the TraceRay arguments of their shaders)\n";
    TextTable rayTypes({"#", "name", "payload", "R", "M", "miss index", "miss record", "InstanceInclusionMask"});
    for (const scenes::RayTypeView& t : v.rayTypes)
        rayTypes.row({std::to_string(t.index), t.name, t.payload, std::to_string(t.rayContribution),
                      std::to_string(t.multiplier), std::to_string(t.missShaderIndex),
                      t.missRecord < 0 ? t.missExport : std::to_string(t.missRecord) + ": " + t.missExport,
                      t.instanceInclusionMask <= 0xFF ? hexText(t.instanceInclusionMask, 2)
                                                      : hexText(t.instanceInclusionMask) + " (low 8 bits: " +
                                                            hexText(t.instanceInclusionMask & 0xFF, 2) + ")"});
    rayTypes.print(out);

    out += "\nInstances (TLAS instance descs; C = InstanceContributionToHitGroupIndex)\n";
    TextTable instances({"InstanceIndex", "name", "InstanceID", "InstanceMask", "flags", "C", "BLAS"});
    for (const scenes::InstanceView& i : v.instances) {
        const std::string blas = i.blas >= 0 ? v.blases[size_t(i.blas)].name
                                 : i.blasAddress == 0 ? std::string("(none: inactive)")
                                                      : hexText(i.blasAddress);
        instances.row({std::to_string(i.instanceIndex), i.name, std::to_string(i.instanceID), hexText(i.instanceMask, 2),
                       i.flagNames, std::to_string(i.contribution), blas});
    }
    instances.print(out);

    out += "\nBLASes (G = GeometryIndex, the position of the geometry in its BLAS)\n";
    TextTable blases({"BLAS", "address", "G", "type", "flags", "primitives"});
    for (const scenes::BlasView& b : v.blases)
        for (const scenes::GeometryView& g : b.geometries)
            blases.row({g.geometryIndex == 0 ? b.name : "", g.geometryIndex == 0 ? hexText(b.address) : "",
                        std::to_string(g.geometryIndex), g.type, g.flagNames, std::to_string(g.primitiveCount)});
    blases.print(out);

    for (const scenes::ShaderTableView& t : v.tables) {
        out += '\n';
        printTable(t, out);
    }

    out += "\nReachability: the hit-group record of every instance x geometry x ray type\n";
    TextTable reach({"InstanceIndex", "instance", "G", "ray type", "I = R + M*G + C", "address", "holds"});
    for (const scenes::ReachView& r : v.reachability) {
        const scenes::InstanceView& inst = v.instances[r.instanceIndex];
        std::string holds = r.holds;
        if (r.maskedOut)
            holds = "(never traversed: InstanceMask " + hexText(inst.instanceMask, 2) + " & InstanceInclusionMask " +
                    hexText(v.rayTypes[r.rayType].instanceInclusionMask & 0xFF, 2) + " = 0)";
        reach.row({std::to_string(r.instanceIndex), inst.name, std::to_string(r.geometryIndex), v.rayTypes[r.rayType].name,
                   r.equation(), hexText(r.address), holds});
    }
    reach.print(out);

    const size_t errors = v.count(TableFinding::Level::Error), warnings = v.count(TableFinding::Level::Warning),
                 notes = v.count(TableFinding::Level::Note);
    out += "\nFindings: " + plural(errors, "error", "errors") + ", " + plural(warnings, "warning", "warnings") + ", " +
           plural(notes, "note", "notes") + "\n";
    for (const TableFinding& f : v.findings) out += "  " + f.format() + "\n";
    return out;
}

std::string formatTableJson(const TableView& v) {
    json::Writer w;
    w.beginObject();
    w.member("scene", v.scene).member("shaderLibrary", v.shaderLibrary).member("precision", v.precision);
    w.member("stateObject", v.stateObject);
    w.key("dispatch").beginObject();
    if (v.compute.shader.empty()) {
        w.member("kind", "DispatchRays");
    } else {
        w.member("kind", "compute");
        w.member("computeShader", v.compute.shader);
        w.key("numThreads").beginArray(json::Writer::Layout::Inline);
        for (uint32_t n : v.compute.numThreads) w.value(n);
        w.endArray();
        w.member("shaderTablesRead", false);
        w.member("text", computeDispatchText(v.compute));
    }
    w.endObject();
    w.key("rayQueryOwners").beginArray();
    for (const scenes::RayQueryOwnerView& o : v.rayQueryOwners) {
        w.beginObject();
        w.member("export", o.exportName).member("stage", o.stage);
        w.key("rayQueries").beginArray();
        for (size_t i = 0; i < o.templateFlags.size(); ++i) {
            w.beginObject(json::Writer::Layout::Inline);
            w.member("templateRayFlags", o.templateFlags[i]);
            w.member("flagNames", dxr::rayFlagsToString(o.templateFlags[i]));
            w.member("declaration", o.declarations()[i]);
            w.endObject();
        }
        w.endArray();
        w.key("hitGroups").beginArray(json::Writer::Layout::Inline);
        for (const std::string& g : o.hitGroups) w.value(g);
        w.endArray();
        w.member("computeDispatch", o.exportName == v.compute.shader);
        if (o.stage == "compute") {
            w.key("numThreads").beginArray(json::Writer::Layout::Inline);
            for (uint32_t n : o.numThreads) w.value(n);
            w.endArray();
        }
        w.endObject();
    }
    w.endArray();

    w.key("rayTypes").beginArray();
    for (const scenes::RayTypeView& t : v.rayTypes) {
        w.beginObject();
        w.member("index", t.index).member("name", t.name).member("payload", t.payload);
        w.member("RayContributionToHitGroupIndex", t.rayContribution);
        w.member("MultiplierForGeometryContributionToHitGroupIndex", t.multiplier);
        w.member("MissShaderIndex", t.missShaderIndex).member("InstanceInclusionMask", t.instanceInclusionMask);
        w.key("missRecord");
        if (t.missRecord < 0) w.null();
        else w.value(t.missRecord);
        w.member("missExport", t.missExport);
        w.endObject();
    }
    w.endArray();

    w.key("instances").beginArray();
    for (const scenes::InstanceView& i : v.instances) {
        w.beginObject();
        w.member("InstanceIndex", i.instanceIndex).member("name", i.name).member("InstanceID", i.instanceID);
        w.member("InstanceMask", i.instanceMask).member("Flags", i.flags).member("flagNames", i.flagNames);
        w.member("InstanceContributionToHitGroupIndex", i.contribution);
        w.key("blas");
        if (i.blas < 0) w.null();
        else w.value(v.blases[size_t(i.blas)].name);
        w.member("AccelerationStructure", i.blasAddress);
        w.endObject();
    }
    w.endArray();

    w.key("blases").beginArray();
    for (const scenes::BlasView& b : v.blases) {
        w.beginObject();
        w.member("name", b.name).member("address", b.address);
        w.key("geometries").beginArray();
        for (const scenes::GeometryView& g : b.geometries) {
            w.beginObject(json::Writer::Layout::Inline);
            w.member("GeometryIndex", g.geometryIndex).member("type", g.type).member("Flags", g.flags);
            w.member("flagNames", g.flagNames).member("primitiveCount", g.primitiveCount);
            w.endObject();
        }
        w.endArray();
        w.endObject();
    }
    w.endArray();

    w.key("tables").beginArray();
    for (const scenes::ShaderTableView& t : v.tables) {
        w.beginObject();
        w.member("table", t.key).member("name", t.name).member("StartAddress", t.startAddress);
        w.member("SizeInBytes", t.sizeInBytes).member("StrideInBytes", t.strideInBytes).member("recordCount", t.recordCount);
        w.key("records").beginArray();
        for (const scenes::RecordView& r : t.records) writeRecord(w, r);
        w.endArray();
        w.endObject();
    }
    w.endArray();

    w.key("reachability").beginArray();
    for (const scenes::ReachView& r : v.reachability) {
        w.beginObject(json::Writer::Layout::Inline);
        w.member("InstanceIndex", r.instanceIndex).member("instance", v.instances[r.instanceIndex].name);
        w.member("GeometryIndex", r.geometryIndex).member("rayType", v.rayTypes[r.rayType].name);
        w.member("R", r.terms.rayContribution).member("M", r.terms.multiplier).member("G", r.terms.geometryIndex);
        w.member("C", r.terms.instanceContribution).member("I", r.terms.index).member("equation", r.equation());
        w.member("address", r.address).member("maskedOut", r.maskedOut);
        w.key("record");
        if (r.record < 0) w.null();
        else w.value(r.record);
        w.member("holds", r.holds);
        w.endObject();
    }
    w.endArray();

    w.key("findings").beginArray();
    for (const TableFinding& f : v.findings) {
        w.beginObject(json::Writer::Layout::Inline);
        w.member("level", scenes::toString(f.level)).member("rule", f.rule).member("message", f.message);
        w.endObject();
    }
    w.endArray();
    w.key("summary").beginObject(json::Writer::Layout::Inline);
    w.member("errors", v.count(TableFinding::Level::Error)).member("warnings", v.count(TableFinding::Level::Warning));
    w.member("notes", v.count(TableFinding::Level::Note));
    w.endObject();
    w.endObject();
    return w.text();
}

CLI::App* addTableCommand(CLI::App& app, TableCommandOptions& o) {
    auto* sub = app.add_subcommand("table", "Show a scene's shader tables as the GPU sees them and check which hit-group "
                                            "record every instance x geometry x ray type reaches");
    sub->footer(kFooter);
    sub->add_option("scene", o.scene, "Scene file (e.g. scenes/proceduray-mandel-julia-pac.json)")->required();
    sub->add_option("--precision", o.precision, "The shader library's precision (its state object and tables): float or double")
        ->check(oneOf({"float", "double"}))
        ->capture_default_str();
    sub->add_flag("--json", o.json, "Print JSON instead of text");
    sub->add_flag("--check", o.check, "Exit with status 1 when there is an error-level finding");
    sub->add_flag("--warnings-as-errors", o.warningsAsErrors, kWarningsAsErrorsHelp);
    return sub;
}

int runTable(const TableCommandOptions& o) {
    try {
        const std::optional<procedural::Precision> precision = procedural::parsePrecision(o.precision);
        REFRAY_CHECK(precision, "--precision expects 'float' or 'double', got '" << o.precision << "'");
        const std::unique_ptr<scenes::Scene> scene = scenes::loadScene(o.scene);
        reportBuildWarnings("table", scene->buildWarnings(), o.warningsAsErrors);
        const TableView view = scenes::buildTableView(*scene, *precision);
        const std::string text = o.json ? formatTableJson(view) : formatTableText(view);
        std::fwrite(text.data(), 1, text.size(), stdout);
        std::fflush(stdout);
        return o.check && view.count(TableFinding::Level::Error) > 0 ? 1 : 0;
    } catch (const Error& e) {
        std::fprintf(stderr, "refray table: %s\n", e.what());
        return 2;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "refray table: unexpected error: %s\n", e.what());
        return 3;
    }
}

}  // namespace refray::tools
