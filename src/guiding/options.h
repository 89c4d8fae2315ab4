// The one table of guide options (--guide-param key=value): every key with the backends that
// take it, the part that reads it, its default, the values it accepts and a line of help.
// The parsers (guiding.cpp's backend parsers, render/integrator.cpp's setupGuiding) take
// their keys, known-key lists and "expected" messages from it; --help and the table of
// docs/GUIDING.md are printed from it (rlpbrt --guide-options), and a test checks that the
// docs list every key with its default. Reasons and measurements behind the defaults are in
// docs/GUIDING.md, not here.
#pragma once

#include <string>
#include <vector>

namespace rlpbrt::guiding {

struct GuideOption {
    enum Backends : unsigned { kHemi = 1, kVdb = 2, kBoth = 3 };
    const char* key;
    unsigned backends;         // which backends accept it
    const char* owner;         // "integrator" (the path integrator and render loop) or "field"
    const char* defaultValue;  // as a user would write it, or a description
    const char* expected;      // the values accepted (the message of a bad value)
    const char* help;          // one line
};

// Every option, in the order of the docs' table.
const std::vector<GuideOption>& guideOptions();
// The option `key` (nullptr if there is none).
const GuideOption* findGuideOption(const std::string& key);
// The option `key` if backend ("hemi" or "vdb") takes it, else nullptr.
const GuideOption* findGuideOption(const std::string& key, const std::string& backend);
// "a, b, c": the keys backend takes, in table order (for unknown-key messages).
std::string knownGuideOptions(const std::string& backend);
// Plain-text lines for --help: key=default, backends, one line of help.
std::string guideOptionsHelp();
// The Markdown table (key, backends, default, values, meaning) for docs/GUIDING.md.
std::string guideOptionsMarkdown();

}  // namespace rlpbrt::guiding
