#include "parser/parser.h"

#include <cfloat>
#include <charconv>
#include <climits>
#include <cmath>
#include <cstdlib>
#include <memory>
#include <unordered_map>
#include <vector>

#include "parser/spd.h"
#include "parser/tokenizer.h"

namespace rlpbrt {

namespace {

enum class Directive {
    Identity, Translate, Scale, Rotate, LookAt, ConcatTransform, Transform, CoordinateSystem,
    CoordSysTransform, ActiveTransform, TransformTimes, ReverseOrientation, Camera, Sampler,
    Film, PixelFilter, Integrator, Accelerator, MakeNamedMedium, MediumInterface, WorldBegin,
    WorldEnd, AttributeBegin, AttributeEnd, TransformBegin, TransformEnd, Texture, Material,
    MakeNamedMaterial, NamedMaterial, LightSource, AreaLightSource, Shape, ObjectBegin,
    ObjectEnd, ObjectInstance, Include, Import
};

const std::unordered_map<std::string_view, Directive>& directiveTable() {
    static const std::unordered_map<std::string_view, Directive> table = {
        {"Identity", Directive::Identity}, {"Translate", Directive::Translate},
        {"Scale", Directive::Scale}, {"Rotate", Directive::Rotate},
        {"LookAt", Directive::LookAt}, {"ConcatTransform", Directive::ConcatTransform},
        {"Transform", Directive::Transform}, {"CoordinateSystem", Directive::CoordinateSystem},
        {"CoordSysTransform", Directive::CoordSysTransform},
        {"ActiveTransform", Directive::ActiveTransform},
        {"TransformTimes", Directive::TransformTimes},
        {"ReverseOrientation", Directive::ReverseOrientation}, {"Camera", Directive::Camera},
        {"Sampler", Directive::Sampler}, {"Film", Directive::Film},
        {"PixelFilter", Directive::PixelFilter}, {"Integrator", Directive::Integrator},
        {"Accelerator", Directive::Accelerator}, {"MakeNamedMedium", Directive::MakeNamedMedium},
        {"MediumInterface", Directive::MediumInterface}, {"WorldBegin", Directive::WorldBegin},
        {"WorldEnd", Directive::WorldEnd}, {"AttributeBegin", Directive::AttributeBegin},
        {"AttributeEnd", Directive::AttributeEnd}, {"TransformBegin", Directive::TransformBegin},
        {"TransformEnd", Directive::TransformEnd}, {"Texture", Directive::Texture},
        {"Material", Directive::Material}, {"MakeNamedMaterial", Directive::MakeNamedMaterial},
        {"NamedMaterial", Directive::NamedMaterial}, {"LightSource", Directive::LightSource},
        {"AreaLightSource", Directive::AreaLightSource}, {"Shape", Directive::Shape},
        {"ObjectBegin", Directive::ObjectBegin}, {"ObjectEnd", Directive::ObjectEnd},
        {"ObjectInstance", Directive::ObjectInstance}, {"Include", Directive::Include},
        {"Import", Directive::Import},
    };
    return table;
}

std::string show(std::string_view t) {
    if (t.size() > 40) return std::string(t.substr(0, 37)) + "...";
    return std::string(t);
}

class Parser {
public:
    Parser(SceneSink& sink, Diagnostics& diag, const ParseLimits& limits)
        : sink_(sink), diag_(diag), limits_(limits) {}

    void run(std::unique_ptr<Tokenizer> root) {
        push(std::move(root));
        Token tok;
        lastMain_ = FileLoc{stack_.empty() ? nullptr : stack_.back()->fileName(), 1, 1};
        while (next(&tok)) {
            // No token of a finished file is referenced any more: `tok` comes from the file
            // on top of the stack. Freeing them bounds memory when files are included often.
            done_.clear();
            if (tok.isString() || tok.isNumberLike() || tok.is('[') || tok.is(']')) {
                diag_.error(tok.loc, "unexpected " + describe(tok) + "; expected a directive");
                skipValues();
                continue;
            }
            auto it = directiveTable().find(tok.text);
            if (it == directiveTable().end()) {
                diag_.error(tok.loc, "unknown directive \"" + show(tok.text) + "\"");
                skipValues();
                continue;
            }
            directive(it->second, tok);
        }
        sink_.endOfFiles(lastMain_);
    }

private:
    // ---- token stream across Includes ----
    void push(std::unique_ptr<Tokenizer> t) {
        char* real = realpath(t->path().c_str(), nullptr);
        openPaths_.push_back(real ? std::string(real) : t->path());
        std::free(real);
        stack_.push_back(std::move(t));
    }

    bool next(Token* tok) {
        if (havePeek_) {
            *tok = peeked_;
            havePeek_ = false;
            return true;
        }
        while (!stack_.empty()) {
            if (stack_.back()->next(tok)) {
                if (stack_.size() == 1) lastMain_ = tok->loc;
                return true;
            }
            // Keep finished files alive: tokens still point into their text.
            done_.push_back(std::move(stack_.back()));
            stack_.pop_back();
            openPaths_.pop_back();
        }
        return false;
    }

    const Token* peek() {
        if (!havePeek_) {
            if (!next(&peeked_)) return nullptr;
            havePeek_ = true;
        }
        return &peeked_;
    }

    static std::string describe(const Token& t) {
        if (t.isString()) return "string " + show(t.text);
        if (t.isNumberLike()) return "number " + show(t.text);
        return "'" + show(t.text) + "'";
    }

    static bool isValueToken(const Token& t) {
        return t.isString() || t.isNumberLike() || t.is('[') || t.is(']') || t.text == "true" ||
               t.text == "false";
    }

    // A bare word that is not a directive name ("nan", a misspelt "ture"): taken as a bad
    // parameter value, so that it is reported as such rather than as an unknown directive.
    static bool isStrayWord(const Token& t) {
        return !isValueToken(t) && directiveTable().count(t.text) == 0;
    }

    // Skips the values after a bad directive, up to the next directive name.
    void skipValues() {
        const Token* p;
        while ((p = peek()) && isValueToken(*p)) {
            Token t;
            next(&t);
        }
    }

    FileLoc endLoc(const FileLoc& after) const { return after; }

    // Parses a number token; values must be finite and fit in a float (tiny values that
    // underflow become 0 or a denormal, as with atof).
    bool parseNumber(const Token& t, double* v) {
        std::string_view s = t.text;
        // from_chars takes no '+', and a second sign after it is not a number.
        if (s.size() >= 2 && s[0] == '+' && s[1] != '-' && s[1] != '+') s.remove_prefix(1);
        const char* b = s.data();
        const char* e = s.data() + s.size();
        auto res = std::from_chars(b, e, *v);
        if (res.ec == std::errc::result_out_of_range && res.ptr == e) {
            // from_chars reports underflow as out of range too; tell the two apart.
            *v = std::strtod(std::string(s).c_str(), nullptr);
            if (std::abs(*v) <= DBL_MIN) res.ec = std::errc();
        }
        if (res.ec == std::errc::result_out_of_range) {
            diag_.error(t.loc, "number " + show(t.text) + " is out of range");
            return false;
        }
        if (res.ec != std::errc() || res.ptr != e || s.empty()) {
            diag_.error(t.loc, "invalid number \"" + show(t.text) + "\"");
            return false;
        }
        if (!std::isfinite(*v)) {
            diag_.error(t.loc, "number " + show(t.text) + " is not finite");
            return false;
        }
        if (std::abs(*v) > double(FLT_MAX)) {
            diag_.error(t.loc, "number " + show(t.text) + " is out of range");
            return false;
        }
        return true;
    }

    // Reads one number argument of a directive.
    bool readNumber(float* out, const Token& dir) {
        Token t;
        const Token* p = peek();
        if (!p || !p->isNumberLike()) {
            diag_.error(p ? p->loc : dir.loc, "\"" + std::string(dir.text) +
                                                   "\" expects a number" +
                                                   (p ? ", found " + describe(*p) : ""));
            return false;
        }
        next(&t);
        double v;
        if (!parseNumber(t, &v)) return false;
        *out = float(v);
        return true;
    }

    bool readNumbers(float* out, int n, const Token& dir) {
        for (int i = 0; i < n; ++i)
            if (!readNumber(&out[i], dir)) {
                skipValues();
                return false;
            }
        return true;
    }

    // Reads a quoted string argument of a directive.
    bool readString(std::string* out, const Token& dir, const char* what) {
        const Token* p = peek();
        if (!p || !p->isString()) {
            diag_.error(p ? p->loc : dir.loc, "\"" + std::string(dir.text) + "\" expects " +
                                                   what + (p ? ", found " + describe(*p) : ""));
            skipValues();
            return false;
        }
        Token t;
        next(&t);
        *out = unquote(t.text);
        return true;
    }

    bool readMatrix(std::array<float, 16>* m, const Token& dir) {
        const Token* p = peek();
        bool bracket = p && p->is('[');
        Token t;
        if (bracket) next(&t);
        if (!readNumbers(m->data(), 16, dir)) return false;
        if (bracket) {
            p = peek();
            if (!p || !p->is(']')) {
                diag_.error(p ? p->loc : dir.loc, "expected ']' after 16 matrix values");
                skipValues();
                return false;
            }
            next(&t);
        }
        return true;
    }

    // Reads the "type name" value... pairs following a directive.
    ParamList readParams() {
        ParamList list(&diag_);
        const Token* p;
        while ((p = peek()) && p->isString()) {
            Token decl;
            next(&decl);
            Param param;
            bool ok = parseDecl(decl, &param);
            // A parameter with any bad value is dropped (after its values are skipped), so
            // that consumers never see a partial array.
            ok = readValues(decl, ok ? &param : nullptr) && ok;
            if (ok) list.add(std::move(param));
        }
        return list;
    }

    bool parseDecl(const Token& decl, Param* param) {
        std::string d = unquote(decl.text);
        std::size_t i = 0, n = d.size();
        auto word = [&](std::string* w) {
            while (i < n && (d[i] == ' ' || d[i] == '\t')) ++i;
            std::size_t s = i;
            while (i < n && d[i] != ' ' && d[i] != '\t') ++i;
            *w = d.substr(s, i - s);
        };
        std::string type, name, extra;
        word(&type);
        word(&name);
        word(&extra);
        if (type.empty() || name.empty() || !extra.empty()) {
            diag_.error(decl.loc, "malformed parameter declaration \"" + show(d) +
                                      "\"; expected \"type name\"");
            return false;
        }
        if (!parseParamType(type, &param->type)) {
            diag_.error(decl.loc, "unknown parameter type \"" + show(type) + "\" in \"" +
                                      show(d) + "\"");
            return false;
        }
        param->name = name;
        param->loc = decl.loc;
        return true;
    }

    // Reads the value(s) of one parameter into `param` (or skips them when it is null).
    // Returns false if an error was reported or `param` was null.
    bool readValues(const Token& decl, Param* param) {
        const Token* p = peek();
        if (!p || !(isValueToken(*p) || isStrayWord(*p)) || p->is(']')) {
            if (param)
                diag_.error(decl.loc, "parameter \"" + param->name + "\" has no value");
            return false;
        }
        Token t;
        if (p->is('[')) {
            next(&t);
            FileLoc open = t.loc;
            while (true) {
                p = peek();
                if (!p) {
                    diag_.error(open, "unterminated '[': end of input before ']'");
                    return false;
                }
                if (p->is(']')) {
                    next(&t);
                    break;
                }
                if (!isValueToken(*p) && !isStrayWord(*p)) {
                    diag_.error(p->loc, "expected ']' to close the '[' at line " +
                                            std::to_string(open.line) + ", found " +
                                            describe(*p));
                    return false;  // leave the directive for the main loop
                }
                if (p->is('[')) {
                    diag_.error(p->loc, "nested '[' in a parameter value");
                    next(&t);
                    param = nullptr;
                    continue;
                }
                next(&t);
                if (param && !addValue(param, t)) param = nullptr;
            }
        } else {
            next(&t);
            if (param && !addValue(param, t)) param = nullptr;
        }
        return param && finishParam(param);
    }

    bool addValue(Param* param, const Token& t) {
        switch (param->type) {
        case ParamType::String:
        case ParamType::Texture:
            if (!t.isString()) return valueError(param, t, "a quoted string");
            param->strings.push_back(unquote(t.text));
            return true;
        case ParamType::Bool: {
            std::string v = t.isString() ? unquote(t.text) : std::string(t.text);
            if (v == "true") param->bools.push_back(1);
            else if (v == "false") param->bools.push_back(0);
            else return valueError(param, t, "true or false");
            return true;
        }
        case ParamType::Spectrum:
            if (t.isString()) {
                if (!param->numbers.empty() || !param->spectrumFile.empty())
                    return valueError(param, t, "either numbers or one .spd file name");
                std::string f = unquote(t.text);
                param->spectrumFile = (f.empty() || f[0] == '/') ? f : t.loc.directory() + f;
                std::string err;
                if (!readSpdFile(param->spectrumFile, &param->numbers, &err)) {
                    diag_.error(t.loc, err);
                    return false;
                }
                return true;
            }
            [[fallthrough]];
        default: {
            if (!t.isNumberLike()) return valueError(param, t, "a number");
            double v;
            if (!parseNumber(t, &v)) return false;
            if (param->type == ParamType::Integer &&
                (v != std::floor(v) || v < INT_MIN || v > INT_MAX)) {
                diag_.error(t.loc, "parameter \"" + param->name + "\" expects an integer, found " +
                                       show(t.text));
                return false;
            }
            if (param->numbers.size() >= limits_.maxValues) {
                diag_.error(t.loc, "too many values for parameter \"" + param->name + "\"");
                return false;
            }
            param->numbers.push_back(v);
            return true;
        }
        }
    }

    bool valueError(Param* param, const Token& t, const char* expected) {
        diag_.error(t.loc, "parameter \"" + std::string(paramTypeName(param->type)) + " " +
                               param->name + "\" expects " + expected + ", found " + describe(t));
        return false;
    }

    // Checks the number of values; false (after reporting) if it is wrong.
    bool finishParam(Param* param) {
        if (param->type == ParamType::Blackbody && param->numbers.size() == 1)
            param->numbers.push_back(1.0);  // pbrt-v4 style single temperature
        int arity = paramTypeArity(param->type);
        if (param->type == ParamType::Spectrum && !param->spectrumFile.empty()) return true;
        if (param->numbers.size() % std::size_t(arity) != 0) {
            diag_.error(param->loc, "parameter \"" + std::string(paramTypeName(param->type)) +
                                        " " + param->name + "\" needs a multiple of " +
                                        std::to_string(arity) + " values, got " +
                                        std::to_string(param->numbers.size()));
            return false;
        }
        if (param->size() == 0) {
            diag_.error(param->loc, "parameter \"" + param->name + "\" has no value");
            return false;
        }
        return true;
    }

    void include(const Token& dir) {
        std::string name;
        if (!readString(&name, dir, "a file name")) return;
        if (name.empty()) {
            diag_.error(dir.loc, "empty file name in " + std::string(dir.text));
            return;
        }
        std::string path = (name.empty() || name[0] == '/') ? name : dir.loc.directory() + name;
        if (int(stack_.size()) >= limits_.maxIncludeDepth) {
            diag_.error(dir.loc, "Include nested more than " +
                                     std::to_string(limits_.maxIncludeDepth) + " levels deep");
            return;
        }
        if (++includeCount_ > kMaxIncludes)
            diag_.fatal(dir.loc, "too many Includes (more than " + std::to_string(kMaxIncludes) +
                                     " files); is the scene an Include bomb?");
        char* real = realpath(path.c_str(), nullptr);
        std::string canon = real ? std::string(real) : path;
        std::free(real);
        for (const auto& open : openPaths_)
            if (open == canon) {
                diag_.error(dir.loc, "cyclic Include of \"" + name + "\"");
                return;
            }
        auto tok = Tokenizer::fromFile(path, diag_, dir.loc);
        if (tok) {
            if (havePeek_) {
                // Cannot happen: Include consumed its argument, and nothing was peeked after.
                havePeek_ = false;
            }
            push(std::move(tok));
        }
    }

    void directive(Directive d, const Token& dir) {
        const FileLoc& loc = dir.loc;
        std::string a, b, c;
        float v[9];
        std::array<float, 16> m;
        switch (d) {
        case Directive::Identity: sink_.identity(loc); break;
        case Directive::Translate:
            if (readNumbers(v, 3, dir)) sink_.translate(v[0], v[1], v[2], loc);
            break;
        case Directive::Scale:
            if (readNumbers(v, 3, dir)) sink_.scale(v[0], v[1], v[2], loc);
            break;
        case Directive::Rotate:
            if (readNumbers(v, 4, dir)) sink_.rotate(v[0], v[1], v[2], v[3], loc);
            break;
        case Directive::LookAt:
            if (readNumbers(v, 9, dir))
                sink_.lookAt(v[0], v[1], v[2], v[3], v[4], v[5], v[6], v[7], v[8], loc);
            break;
        case Directive::ConcatTransform:
            if (readMatrix(&m, dir)) sink_.concatTransform(m, loc);
            break;
        case Directive::Transform:
            if (readMatrix(&m, dir)) sink_.transform(m, loc);
            break;
        case Directive::CoordinateSystem:
            if (readString(&a, dir, "a name")) sink_.coordinateSystem(a, loc);
            break;
        case Directive::CoordSysTransform:
            if (readString(&a, dir, "a name")) sink_.coordSysTransform(a, loc);
            break;
        case Directive::ActiveTransform: {
            const Token* p = peek();
            Token t;
            if (p && (p->text == "StartTime" || p->text == "EndTime" || p->text == "All")) {
                next(&t);
                sink_.activeTransform(std::string(t.text), loc);
            } else {
                diag_.error(p ? p->loc : loc,
                            "ActiveTransform expects StartTime, EndTime or All");
                if (p && p->isString()) next(&t);
            }
            break;
        }
        case Directive::TransformTimes:
            if (readNumbers(v, 2, dir)) sink_.transformTimes(v[0], v[1], loc);
            break;
        case Directive::ReverseOrientation: sink_.reverseOrientation(loc); break;
        case Directive::Camera:
            if (readString(&a, dir, "a camera type")) sink_.camera(a, readParams(), loc);
            break;
        case Directive::Sampler:
            if (readString(&a, dir, "a sampler type")) sink_.sampler(a, readParams(), loc);
            break;
        case Directive::Film:
            if (readString(&a, dir, "a film type")) sink_.film(a, readParams(), loc);
            break;
        case Directive::PixelFilter:
            if (readString(&a, dir, "a filter type")) sink_.pixelFilter(a, readParams(), loc);
            break;
        case Directive::Integrator:
            if (readString(&a, dir, "an integrator type")) sink_.integrator(a, readParams(), loc);
            break;
        case Directive::Accelerator:
            if (readString(&a, dir, "an accelerator type")) sink_.accelerator(a, readParams(), loc);
            break;
        case Directive::MakeNamedMedium:
            if (readString(&a, dir, "a medium name")) sink_.makeNamedMedium(a, readParams(), loc);
            break;
        case Directive::MediumInterface: {
            if (!readString(&a, dir, "a medium name")) break;
            const Token* p = peek();
            if (p && p->isString()) {
                Token t;
                next(&t);
                b = unquote(t.text);
            } else {
                b = a;
            }
            sink_.mediumInterface(a, b, loc);
            break;
        }
        case Directive::WorldBegin: sink_.worldBegin(loc); break;
        case Directive::WorldEnd: sink_.worldEnd(loc); break;
        case Directive::AttributeBegin: sink_.attributeBegin(loc); break;
        case Directive::AttributeEnd: sink_.attributeEnd(loc); break;
        case Directive::TransformBegin: sink_.transformBegin(loc); break;
        case Directive::TransformEnd: sink_.transformEnd(loc); break;
        case Directive::Texture:
            if (readString(&a, dir, "a texture name") && readString(&b, dir, "a texture type") &&
                readString(&c, dir, "a texture class"))
                sink_.texture(a, b, c, readParams(), loc);
            break;
        case Directive::Material:
            if (readString(&a, dir, "a material type")) sink_.material(a, readParams(), loc);
            break;
        case Directive::MakeNamedMaterial:
            if (readString(&a, dir, "a material name"))
                sink_.makeNamedMaterial(a, readParams(), loc);
            break;
        case Directive::NamedMaterial:
            if (readString(&a, dir, "a material name")) sink_.namedMaterial(a, loc);
            break;
        case Directive::LightSource:
            if (readString(&a, dir, "a light type")) sink_.lightSource(a, readParams(), loc);
            break;
        case Directive::AreaLightSource:
            if (readString(&a, dir, "an area light type"))
                sink_.areaLightSource(a, readParams(), loc);
            break;
        case Directive::Shape:
            if (readString(&a, dir, "a shape type")) sink_.shape(a, readParams(), loc);
            break;
        case Directive::ObjectBegin:
            if (readString(&a, dir, "an object name")) sink_.objectBegin(a, loc);
            break;
        case Directive::ObjectEnd: sink_.objectEnd(loc); break;
        case Directive::ObjectInstance:
            if (readString(&a, dir, "an object name")) sink_.objectInstance(a, loc);
            break;
        case Directive::Import:
            diag_.warning(loc, "Import is a pbrt-v4 directive; treated as Include");
            [[fallthrough]];
        case Directive::Include: include(dir); break;
        }
    }

    SceneSink& sink_;
    Diagnostics& diag_;
    ParseLimits limits_;
    std::vector<std::unique_ptr<Tokenizer>> stack_, done_;
    std::vector<std::string> openPaths_;
    Token peeked_;
    bool havePeek_ = false;
    FileLoc lastMain_;  // the last token read from the main file
    // Files opened by Include in total; bounds the work of exponential Include fan-out.
    static constexpr int kMaxIncludes = 10000;
    int includeCount_ = 0;
};

bool runParser(std::unique_ptr<Tokenizer> root, SceneSink& sink, Diagnostics& diag,
               const ParseLimits& limits) {
    int before = diag.errorCount();
    if (!root) return false;
    Parser parser(sink, diag, limits);
    try {
        parser.run(std::move(root));
    } catch (const FatalError&) {
        return false;
    }
    return diag.errorCount() == before;
}

}  // namespace

bool parseFile(const std::string& path, SceneSink& sink, Diagnostics& diag,
               const ParseLimits& limits) {
    FileLoc none{diag.intern(path), 0, 0};
    return runParser(Tokenizer::fromFile(path, diag, none), sink, diag, limits);
}

bool parseString(const std::string& text, const std::string& name, SceneSink& sink,
                 Diagnostics& diag, const ParseLimits& limits) {
    return runParser(Tokenizer::fromString(text, name, diag), sink, diag, limits);
}

}  // namespace rlpbrt
