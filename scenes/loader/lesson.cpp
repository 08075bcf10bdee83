// Lesson files (refray-lesson/1, docs/tutorial-indexing.md): a base scene or lesson with a JSON Patch applied.
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>

#include "core/file_input.h"
#include "core/json_writer.h"
#include "scenes/loader/parse_context.h"
#include "scenes/scene_loader.h"

namespace refray::scenes::loader {

Value resolveLesson(Value root, const std::string& fileName, uint32_t depth, std::string& hashed, LessonDesc& lesson) {
    const Value* format = root.isObject() ? root.find("format") : nullptr;
    if (!format || !format->isString() || format->asString() != kLessonFormat) return root;
    if (depth >= 8) root.fail("lessons are based on each other more than 8 deep (a cycle?)");
    ObjectReader r(root, "a lesson");
    r.required("format");
    const Value& name = r.required("name");
    const Value& base = r.required("base");
    const Value& title = r.required("title");
    const Value* teaches = r.optional("teaches");
    const Value& patch = r.required("patch");
    const Value* expect = r.optional("expect");
    r.finish();
    const std::filesystem::path basePath = std::filesystem::path(fileName).parent_path() / base.asString();
    std::string baseText;
    try {
        baseText = readInputFile(basePath.string(), "the lesson's base");
    } catch (const Error& e) {
        base.fail(e.what());
    }
    hashed += baseText;
    LessonDesc inner;
    Value document = resolveLesson(json::parse(baseText, basePath.string()), basePath.string(), depth + 1, hashed, inner);
    json::applyPatch(document, patch);
    if (depth == 0) {
        lesson.title = title.asString();
        if (teaches) lesson.teaches = teaches->asString();
        lesson.base = base.asString();
        if (expect) {
            ObjectReader er(*expect, "the lesson's 'expect'");
            if (const Value* v = er.optional("table")) lesson.expectTable = v->asString();
            if (const Value* v = er.optional("render")) {
                ObjectReader rr(*v, "the lesson's expected render");
                if (const Value* c = rr.optional("camera")) lesson.renderCamera = c->asString();
                if (const Value* z = rr.optional("size")) lesson.renderSize = z->asString();
                lesson.expectRender = rr.required("diagnostic").asString();
                if (const Value* i = rr.optional("image")) {
                    if (!i->isString() || (i->asString() != "same-as-base" && i->asString() != "differs-from-base"))
                        i->fail("the lesson's expected image is \"same-as-base\" or \"differs-from-base\"");
                    lesson.expectImage = i->asString();
                }
                rr.finish();
            }
            er.finish();
        }
    }
    // The lesson's name replaces the base's (renders and messages name the lesson).
    const std::string nameJson = "[{\"op\": \"replace\", \"path\": \"/name\", \"value\": " + json::quoted(name.asString()) + "}]";
    json::applyPatch(document, json::parse(nameJson, fileName));
    return document;
}

}  // namespace refray::scenes::loader
