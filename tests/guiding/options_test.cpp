// The table of guide options (guiding/options.h) against the parsers that read it and the
// docs that describe it.
#include <fstream>
#include <set>
#include <sstream>

#include <gtest/gtest.h>

#include "guiding/guiding.h"
#include "guiding/options.h"
#include "guiding/test_scenes.h"

namespace rlpbrt::guiding {
namespace {

// A default that is a value a user could write (not a description such as "hemi: 1024; ...").
bool literalDefault(const GuideOption& o) {
    const std::string d = o.defaultValue;
    return d.find(' ') == std::string::npos && d.find(':') == std::string::npos;
}

TEST(GuideOptions, KeysAreUniqueAndFound) {
    std::set<std::string> keys;
    for (const GuideOption& o : guideOptions()) {
        EXPECT_TRUE(keys.insert(o.key).second) << o.key;
        EXPECT_EQ(findGuideOption(o.key), &o);
        EXPECT_NE(o.backends, 0u);
        EXPECT_TRUE(std::string(o.owner) == "integrator" || std::string(o.owner) == "field");
    }
    EXPECT_EQ(findGuideOption("no-such-key"), nullptr);
    EXPECT_NE(findGuideOption("knn", "hemi"), nullptr);
    EXPECT_EQ(findGuideOption("knn", "vdb"), nullptr);
    EXPECT_EQ(findGuideOption("voxel", "hemi"), nullptr);
}

// Every backend accepts each of its keys at the table's default, and refuses the others by
// name, listing exactly the table's keys as known.
TEST(GuideOptions, ParsersAcceptTheTableAndNothingElse) {
    const SceneInfo scene = test::cornerScene();
    for (const char* backend : {"hemi", "vdb"}) {
        for (const GuideOption& o : guideOptions()) {
            GuideConfig config;
            config.backend = backend;
            config.params[o.key] = literalDefault(o) ? o.defaultValue : "1";
            if (std::string(o.key) == "voxel-size" || std::string(o.key) == "voxel")
                config.params[o.key] = "8";
            std::string error;
            auto field = createGuidingField(config, scene, &error);
            if (o.backends & (std::string(backend) == "hemi" ? GuideOption::kHemi
                                                             : GuideOption::kVdb)) {
                EXPECT_NE(field, nullptr) << backend << " " << o.key << ": " << error;
            } else {
                EXPECT_EQ(field, nullptr) << backend << " " << o.key;
                EXPECT_NE(error.find("unknown parameter '" + std::string(o.key) + "'"),
                          std::string::npos)
                    << error;
                EXPECT_NE(error.find(knownGuideOptions(backend)), std::string::npos) << error;
            }
        }
    }
}

// A bad value's message says what the table says the key accepts.
TEST(GuideOptions, BadValueMessagesComeFromTheTable) {
    const SceneInfo scene = test::cornerScene();
    GuideConfig config;
    config.backend = "hemi";
    config.params["knn"] = "0";
    std::string error;
    EXPECT_EQ(createGuidingField(config, scene, &error), nullptr);
    EXPECT_NE(error.find(findGuideOption("knn")->expected), std::string::npos) << error;
}

// docs/GUIDING.md's table names every key with its default.
TEST(GuideOptions, DocsListEveryKeyWithItsDefault) {
    std::ifstream f(std::string(RLPBRT_SOURCE_DIR) + "/docs/GUIDING.md");
    ASSERT_TRUE(f.good()) << "docs/GUIDING.md is missing";
    std::stringstream ss;
    ss << f.rdbuf();
    const std::string docs = ss.str();
    for (const GuideOption& o : guideOptions()) {
        const std::string row = "| `" + std::string(o.key) + "` |";
        const size_t at = docs.find(row);
        ASSERT_NE(at, std::string::npos) << "no table row for " << o.key;
        const std::string line = docs.substr(at, docs.find('\n', at) - at);
        if (!literalDefault(o)) continue;
        // The default is a column of its own, plain or as code.
        const std::string plain = std::string("| ") + o.defaultValue + " |";
        const std::string code = std::string("| `") + o.defaultValue + "` |";
        EXPECT_TRUE(line.find(plain) != std::string::npos || line.find(code) != std::string::npos)
            << o.key << " (default " << o.defaultValue << "): " << line;
    }
}

}  // namespace
}  // namespace rlpbrt::guiding
