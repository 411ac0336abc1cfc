// Every reference image in reference-images/MANIFEST.json is checked against a quick render of its
// scene by another estimator (or another MIS heuristic), with compare's statistics, which
// account for the reference's own variance (docs/compare.md). Entries added to the manifest are
// tested without changing this file. Each check's spp gives compare its 10 effective samples in
// most pixels (reference-images/generate.py says why where it is above 32): with fewer the answer
// is "insufficient samples", which this test rejects (REQUIRE hasVerdict).
#include "bdptref/exr_io.h"
#include "bdptref/image_compare.h"
#include "support/render_util.h"

#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>

#include <fstream>

using namespace bdptref;
using namespace bdptref::test;

TEST_CASE("Quick renders by another estimator are consistent with every reference image", "[references]") {
    std::ifstream f(sourcePath("reference-images/MANIFEST.json"));
    REQUIRE(f);
    const nlohmann::json manifest = nlohmann::json::parse(f);
    const auto& refs = manifest.at("references");
    REQUIRE(refs.size() >= 8);  // every shipped scene (scenes/README.md) has an entry
    const std::string dir = makeTempDir("references");
    for (const auto& [name, e] : refs.items()) {
        DYNAMIC_SECTION(name) {
            const auto& check = e.at("check");
            std::string args = "render " + sourcePath(e.at("scene").get<std::string>()) + " -o " + dir + "/" + name +
                               ".exr --width " + std::to_string(manifest.at("width").get<int>()) + " --height " +
                               std::to_string(manifest.at("height").get<int>()) + " --integrator " +
                               check.at("integrator").get<std::string>() + " --spp " +
                               std::to_string(check.at("spp").get<int>()) + " --seed " +
                               std::to_string(check.at("seed").get<int>()) + " -q --no-preview";
            // Option values under scenes/ (e.g. --env-map scenes/env-map-sky.hdr) are repository paths.
            auto arg = [](const std::string& o) { return o.rfind("scenes/", 0) == 0 ? sourcePath(o) : o; };
            for (const auto& o : e.at("options")) args += " " + arg(o.get<std::string>());
            for (const auto& o : check.at("options")) args += " " + o.get<std::string>();
            std::string out;
            INFO(args);
            REQUIRE(runCli(args, &out) == 0);
            const ExrImage test = readImage(dir + "/" + name + ".exr");
            const ExrImage ref = readImage(sourcePath("reference-images/" + e.at("reference").get<std::string>()));
            // A stale reference (the scene file changed since) is an error of its own. An entry that
            // shares another file's image (the same content in another container) has its own hash.
            if (!e.contains("sharedWith"))
                CHECK(test.attributes.at("bdptref:sceneHash") == ref.attributes.at("bdptref:sceneHash"));
            CHECK(test.attributes.at("bdptref:maxDepth") == ref.attributes.at("bdptref:maxDepth"));
            // An environment map is recorded with its path ("map /abs/dir/sky.hdr ..."): the reference
            // was made in another checkout, so only the file name and the settings must agree.
            auto environment = [](std::string attr) {
                const size_t slash = attr.rfind('/');
                if (attr.rfind("map ", 0) == 0 && slash != std::string::npos) attr = "map " + attr.substr(slash + 1);
                return attr;
            };
            CHECK(environment(test.attributes.at("bdptref:environment")) == environment(ref.attributes.at("bdptref:environment")));
            const CompareResult r = compareImages(test, ref);  // alpha 0.01, Welch with the pooled bound
            INFO(formatCompareReport(r, name + " (" + check.at("integrator").get<std::string>() + ")", "reference"));
            REQUIRE(r.hasVerdict);
            CHECK(r.tested >= 1000);  // the verdict rests on a quarter of the image or more
            CHECK(r.consistent);
        }
    }
}
