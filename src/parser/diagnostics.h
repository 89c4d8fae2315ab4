// Diagnostics: source locations and compiler-style messages ("file:line:col: error: msg").
// Standard library only; shared by the parser and everything that reports scene errors.
#pragma once

#include <cstddef>
#include <deque>
#include <iosfwd>
#include <memory>
#include <stdexcept>
#include <string>
#include <unordered_map>
#include <vector>

namespace rlpbrt {

// A position in a scene file. `file` points at an interned, stable string (see
// Diagnostics::intern) or is null for "no location". Lines and columns count from 1.
struct FileLoc {
    const std::string* file = nullptr;
    int line = 0;
    int col = 0;

    // "file:line:col", "file" when line is 0, "<unknown>" without a file.
    std::string str() const;
    // Directory of `file` (with trailing '/'), or "" when there is none.
    std::string directory() const;
};

enum class Severity { Warning, Error };

struct Diagnostic {
    Severity severity;
    FileLoc loc;
    std::string message;
    std::string str() const;  // "file:line:col: error: message"
};

// Thrown for errors after which parsing cannot go on (unreadable file, broken syntax).
struct FatalError : std::runtime_error {
    explicit FatalError(const std::string& what) : std::runtime_error(what) {}
};

// Collects and prints diagnostics. Errors are recorded and printed immediately; the caller
// decides when to stop (errorCount() > 0 after parsing = fatal). fatal() records and throws.
class Diagnostics {
public:
    Diagnostics();
    // Where messages are printed; null silences printing (messages are still recorded).
    void setStream(std::ostream* os) { stream_ = os; }

    void error(const FileLoc& loc, const std::string& message);
    void warning(const FileLoc& loc, const std::string& message);
    [[noreturn]] void fatal(const FileLoc& loc, const std::string& message);

    // Record a scene feature that is parsed but ignored (printed as a warning once per
    // distinct message; the summary lists them all with their counts). An error in strict
    // mode.
    void ignored(const FileLoc& loc, const std::string& feature);
    // Record input that pbrt-v3 tolerates with a substitute (an undefined named material, an
    // unknown material type, an unreadable image): a warning naming the substitute, or an
    // error in strict mode. Listed with the ignored features.
    void substituted(const FileLoc& loc, const std::string& what) { ignored(loc, what); }

    // Strict mode (--strict): ignored features and substitutions are errors.
    void setStrict(bool strict) { strict_ = strict; }
    bool strict() const { return strict_; }

    int errorCount() const { return errors_; }
    int warningCount() const { return warnings_; }
    const std::vector<Diagnostic>& all() const { return all_; }
    // Ignored features with how often each occurred, in first-seen order.
    const std::vector<std::pair<std::string, int>>& ignoredFeatures() const { return ignored_; }

    // A stable pointer for a file name, to be stored in FileLocs.
    const std::string* intern(const std::string& filename);

    // Identical warnings beyond this count are counted but not printed.
    static constexpr int kMaxRepeats = 5;

private:
    void emit(Severity s, const FileLoc& loc, const std::string& message);

    std::ostream* stream_;
    bool strict_ = false;
    int errors_ = 0, warnings_ = 0;
    std::vector<Diagnostic> all_;
    std::unordered_map<std::string, int> repeats_;
    std::vector<std::pair<std::string, int>> ignored_;
    std::unordered_map<std::string, std::size_t> ignoredIndex_;
    std::deque<std::string> names_;
    std::unordered_map<std::string, const std::string*> nameIndex_;
};

}  // namespace rlpbrt
