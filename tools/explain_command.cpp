#include "tools/explain_command.h"

#include <algorithm>
#include <cstdio>
#include <limits>
#include <set>
#include <sstream>

#include "core/error.h"
#include "core/json_writer.h"
#include "core/strings.h"
#include "inspect/explain.h"
#include "tools/cli_common.h"

namespace refray::tools {

CLI::App* addExplainCommand(CLI::App& app, ExplainCommandOptions& o) {
    CLI::App* c = app.add_subcommand("explain", "The whole ray tree of one pixel: every TraceRay, candidate, record "
                                                "index (R + M×G + C), shader call and payload");
    c->add_option("scene", o.scene, "Scene file (e.g. scenes/proceduray-mandel-julia-pac.json)")->required();
    c->add_option("--pixel", o.pixel, "The pixel X,Y (0,0 = top left), as in the rendered image");
    c->add_option("--camera", o.camera, "Camera name (default: the scene's defaultCamera)");
    c->add_option("--size", o.size, "Image size WIDTHxHEIGHT (default: the scene's imageSize)");
    c->add_option("--time", o.time, "Animation time in seconds (default: the scene's default time)")->check(seconds());
    c->add_option("--precision", o.precision, "Shader math precision: float or double")->capture_default_str();
    c->add_option("--order", o.order, "Traversal order: ordered (default) or adversarial (GEN-3)");
    c->add_option("--seed", o.seed, "Seed of the adversarial order")
        ->check(wholeNumber("a seed from 0 to 18446744073709551615", 0, std::numeric_limits<uint64_t>::max()));
    c->add_flag("--warnings-as-errors", o.warningsAsErrors, kWarningsAsErrorsHelp);
    c->add_flag("--json", o.json, "Write JSON (format refray-explain/1) instead of text");
    c->add_option("-o,--output", o.output, "Write to this file instead of stdout");
    c->add_option("--html", o.html,
                  "Write an interactive page: the render, and each pixel's ray tree on hover (default size: a quarter of "
                  "the scene's imageSize in each direction)");
    return c;
}

namespace {

// The page: the render enlarged, and a panel that shows the hovered (or clicked) pixel's rays, built by the
// script from a compact per-pixel list: "depth R M miss flags instance geometry primitive C I t" per ray,
// instance -1 for a miss, rays separated by ';'.
std::string explainPage(const scenes::PixelTrees& trees, const scenes::SceneDesc& desc, const std::string& title,
                        const std::string& command, const std::string& pixel) {
    std::ostringstream page;
    const uint32_t scale = std::max(1u, 960u / std::max(1u, trees.width));
    Image shown = trees.image;
    for (vec4& p : shown.pixels()) p.a = 1.0f;  // the shaders' alpha is not coverage
    std::set<uint32_t> flagValues;
    page << "<!doctype html>\n<html><head><meta charset=\"utf-8\"><title>" << htmlEscape(title) << "</title>\n"
         << "<style>body{font-family:sans-serif;background:#1e1e1e;color:#ddd;margin:16px}"
            "#wrap{display:flex;gap:16px;align-items:flex-start}"
            "#render{image-rendering:pixelated;cursor:crosshair;border:1px solid #555}"
            "#panel{flex:1;min-width:420px}#explanation{background:#111;padding:8px;white-space:pre-wrap;"
            "font-size:13px;line-height:1.35}code{color:#9cf}</style></head>\n<body>\n";
    page << "<h1>" << htmlEscape(title) << "</h1>\n<p>Hover a pixel to see its rays; click to pin it. For every "
         << "candidate, shader call and payload run the command under the panel.</p>\n";
    page << "<div id=\"wrap\"><img id=\"render\" width=\"" << trees.width * scale << "\" height=\"" << trees.height * scale
         << "\" src=\"" << pngDataURI(shown) << "\" alt=\"the render\">\n";
    page << "<div id=\"panel\"><div id=\"pixel\">no pixel selected</div><pre id=\"explanation\"></pre>"
         << "<p><code id=\"command\"></code></p></div></div>\n<script>\n";
    page << "const W=" << trees.width << ",H=" << trees.height << ",S=" << scale << ";\n";
    page << "const command=" << json::quoted(command) << ";\n";
    std::vector<std::string> names;
    for (const scenes::InstanceDescFile& i : desc.instances) names.push_back(json::quoted(i.name));
    page << "const instances=[" << joined(names) << "];\n";
    names.clear();
    for (const scenes::RecordDesc& r : desc.hitGroupRecords) names.push_back(r.hitGroup.empty() ? "null" : json::quoted(r.hitGroup));
    page << "const records=[" << joined(names) << "];\n";
    names.clear();
    for (const std::string& m : desc.missRecords) names.push_back(m.empty() ? "null" : json::quoted(m));
    page << "const missRecords=[" << joined(names) << "];\n";
    names.clear();
    for (const scenes::RayTypeDesc& t : desc.rayTypes)
        names.push_back("[" + json::quoted(t.name) + "," + std::to_string(t.rayContribution) + "," + std::to_string(t.multiplier) +
                        "," + std::to_string(t.missShaderIndex) + "]");
    page << "const rayTypes=[" << joined(names) << "];\n";
    page << "const rays=[\n";
    for (size_t p = 0; p < trees.rays.size(); ++p) {
        std::string list;
        for (const scenes::RaySummary& r : trees.rays[p]) {
            flagValues.insert(r.rayFlags);
            if (!list.empty()) list += ";";
            list += std::to_string(r.depth) + " " + std::to_string(r.rayContribution) + " " + std::to_string(r.multiplier) +
                    " " + std::to_string(r.missShaderIndex) + " " + std::to_string(r.rayFlags) + " ";
            list += r.hit ? std::to_string(r.instanceIndex) + " " + std::to_string(r.geometryIndex) + " " +
                                std::to_string(r.primitiveIndex) + " " + std::to_string(r.terms.instanceContribution) +
                                " " + std::to_string(r.terms.index) + " " + shortestFloat(r.t)
                          : std::string("-1 0 0 0 0 0");
        }
        page << "\"" << list << "\"" << (p + 1 < trees.rays.size() ? "," : "") << ((p + 1) % 8 == 0 ? "\n" : "");
    }
    page << "];\n";
    names.clear();
    for (uint32_t f : flagValues) names.push_back(json::quoted(std::to_string(f)) + ":" + json::quoted(dxr::rayFlagsToString(f)));
    page << "const flagNames={" << joined(names) << "};\n";
    page << R"JS(
function q(s){return "'"+s+"'";}
function explain(x,y){
  if(x<0||y<0||x>=W||y>=H)return;
  const out=[];
  for(const ray of rays[y*W+x].split(';')){
    if(!ray)continue;
    const [d,R,M,miss,flags,inst,geom,prim,C,I,t]=ray.split(' ');
    const pad='  '.repeat(Number(d)-1);
    const type=rayTypes.find(r=>r[1]==R&&r[2]==M&&r[3]==miss);
    out.push(pad+'TraceRay depth '+d+(type?' '+q(type[0]):'')+': R = '+R+', M = '+M+', MissShaderIndex = '+miss+', '+flagNames[flags]);
    if(inst==='-1'){
      const m=Number(miss)&0xFFFF;
      out.push(pad+'  miss -> miss record '+m+' '+(m<missRecords.length&&missRecords[m]?q(missRecords[m]):'NULL'));
    }else{
      const G=Number(geom);
      out.push(pad+'  hit instance '+inst+' '+q(instances[Number(inst)])+', geometry '+geom+', primitive '+prim+' at t = '+t);
      out.push(pad+'  I = R + M×G + C = '+(Number(R)&15)+' + '+(Number(M)&15)+'×'+G+' + '+C+' = '+I+
               ' -> record '+I+' '+(Number(I)<records.length?(records[Number(I)]?q(records[Number(I)]):'NULL'):'(past the end of the table)'));
    }
  }
  document.getElementById('pixel').textContent='pixel ('+x+', '+y+')';
  document.getElementById('explanation').textContent=out.join('\n');
  document.getElementById('command').textContent=command+' --pixel '+x+','+y;
}
const img=document.getElementById('render');
let pinned=false;
img.addEventListener('mousemove',e=>{if(!pinned)explain(Math.floor(e.offsetX/S),Math.floor(e.offsetY/S));});
img.addEventListener('click',e=>{pinned=!pinned;explain(Math.floor(e.offsetX/S),Math.floor(e.offsetY/S));});
const m=/pixel=(\d+),(\d+)/.exec(location.hash);
)JS";
    page << "const initial=m?[Number(m[1]),Number(m[2])]:" << (pixel.empty() ? "null" : "[" + pixel + "]") << ";\n";
    page << "if(initial){pinned=true;explain(initial[0],initial[1]);}\n</script>\n</body></html>\n";
    return page.str();
}

}  // namespace

int runExplain(const ExplainCommandOptions& o) {
    REFRAY_CHECK(!o.pixel.empty() || !o.html.empty(), "refray explain needs --pixel X,Y (or --html PAGE for every pixel)");
    const std::vector<NamedPath> outputs{{"-o", o.output}, {"--html", o.html}};
    checkOutputs({{"scene file", o.scene}}, outputs);
    std::unique_ptr<scenes::Scene> scene = scenes::loadScene(o.scene);
    const scenes::SceneDesc& desc = scene->desc();
    std::vector<NamedPath> inputs{{"scene file", o.scene}};
    for (const scenes::ModelDesc& m : desc.models) inputs.push_back({"model file", m.file.string()});
    checkOutputs(inputs, outputs);
    reportBuildWarnings("explain", scene->buildWarnings(), o.warningsAsErrors);
    const Size size = !o.size.empty() ? parseSize(o.size)
                      : o.html.empty() ? Size{desc.defaultWidth, desc.defaultHeight}
                                       : Size{std::max(1u, desc.defaultWidth / 4), std::max(1u, desc.defaultHeight / 4)};
    uint32_t x = 0, y = 0;
    if (!o.pixel.empty()) parsePixel(o.pixel, x, y);
    scenes::RenderSettings settings;
    settings.width = size.width;
    settings.height = size.height;
    settings.camera = o.camera;
    settings.time = o.time;
    const std::optional<procedural::Precision> precision = procedural::parsePrecision(o.precision);
    REFRAY_CHECK(precision, "--precision expects 'float' or 'double', got '" << o.precision << "'");
    settings.precision = *precision;
    REFRAY_CHECK(o.order == "ordered" || o.order == "adversarial",
                 "--order expects 'ordered' or 'adversarial', got '" << o.order << "'");
    settings.order = o.order == "adversarial" ? dxr::TraversalOrder::Adversarial : dxr::TraversalOrder::Ordered;
    settings.adversarialSeed = o.seed;

    if (!o.html.empty()) {
        REFRAY_CHECK(o.pixel.empty() || (x < size.width && y < size.height),
                     "--pixel " << o.pixel << " is outside the " << size.width << "x" << size.height << " image");
        settings.progress = terminalProgress();
        const scenes::PixelTrees trees = scenes::explainAllPixels(*scene, settings);
        const std::string title = "refray explain: " + desc.name + ", camera " + desc.camera(o.camera).name + ", " +
                                  std::to_string(size.width) + "x" + std::to_string(size.height);
        std::string command = "refray explain " + o.scene + " --size " + std::to_string(size.width) + "x" + std::to_string(size.height);
        if (!o.camera.empty()) command += " --camera " + o.camera;
        if (o.time) command += " --time " + shortestFloat(*o.time);
        if (o.precision != "float") command += " --precision " + o.precision;
        writeTextFile(o.html, explainPage(trees, desc, title, command, o.pixel));
        std::printf("wrote %s (hover a pixel to see its rays)\n", o.html.c_str());
        return 0;
    }
    const scenes::Explanation explanation = scenes::explainPixel(*scene, settings, x, y);
    const std::string text = o.json ? scenes::explanationJson(explanation, scene->desc())
                                    : scenes::formatExplanation(explanation, scene->desc());
    if (o.output.empty()) {
        std::fwrite(text.data(), 1, text.size(), stdout);
    } else {
        writeTextFile(o.output, text);
        std::printf("wrote %s\n", o.output.c_str());
    }
    return explanation.error ? 1 : 0;
}

}  // namespace refray::tools
