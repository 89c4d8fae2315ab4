#include "parser/diagnostics.h"

#include <iostream>
#include <sstream>

namespace rlpbrt {

std::string FileLoc::str() const {
    if (!file) return "<unknown>";
    if (line <= 0) return *file;
    return *file + ":" + std::to_string(line) + ":" + std::to_string(col);
}

std::string FileLoc::directory() const {
    if (!file) return "";
    auto slash = file->find_last_of('/');
    return slash == std::string::npos ? std::string() : file->substr(0, slash + 1);
}

std::string Diagnostic::str() const {
    return loc.str() + (severity == Severity::Error ? ": error: " : ": warning: ") + message;
}

Diagnostics::Diagnostics() : stream_(&std::cerr) {}

void Diagnostics::emit(Severity s, const FileLoc& loc, const std::string& message) {
    Diagnostic d{s, loc, message};
    if (s == Severity::Error) ++errors_; else ++warnings_;
    // Repeated identical warnings (same text, any location) are printed a few times only.
    int count = s == Severity::Warning ? ++repeats_[message] : 1;
    if (stream_ && count <= kMaxRepeats) {
        *stream_ << d.str() << "\n";
        if (count == kMaxRepeats)
            *stream_ << loc.str() << ": note: further identical warnings are not shown\n";
    }
    if (all_.size() < 100000) all_.push_back(std::move(d));
}

void Diagnostics::error(const FileLoc& loc, const std::string& message) {
    emit(Severity::Error, loc, message);
}

void Diagnostics::warning(const FileLoc& loc, const std::string& message) {
    emit(Severity::Warning, loc, message);
}

void Diagnostics::fatal(const FileLoc& loc, const std::string& message) {
    emit(Severity::Error, loc, message);
    throw FatalError(loc.str() + ": error: " + message);
}

void Diagnostics::ignored(const FileLoc& loc, const std::string& feature) {
    if (strict_) {
        error(loc, feature + " [--strict]");
        return;
    }
    auto it = ignoredIndex_.find(feature);
    if (it == ignoredIndex_.end()) {
        ignoredIndex_[feature] = ignored_.size();
        ignored_.emplace_back(feature, 1);
        warning(loc, feature);
    } else {
        ++ignored_[it->second].second;
    }
}

const std::string* Diagnostics::intern(const std::string& filename) {
    auto it = nameIndex_.find(filename);
    if (it != nameIndex_.end()) return it->second;
    names_.push_back(filename);
    const std::string* p = &names_.back();
    nameIndex_[filename] = p;
    return p;
}

}  // namespace rlpbrt
