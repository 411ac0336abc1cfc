// `bdptref diagnose REPORT.json`: the ranked diagnosis of a saved validate report, again
// (docs/diagnosis.md, "Diagnosing a saved report"): with a newer catalogue or suite, another
// signatures file, or one bug's signature left out (how tools/validate_classifier.py measures the
// diagnosis leave-one-out without rendering again).
#include "bdptref/errors.h"
#include "cli/commands.h"
#include "verify/validate_diagnosis.h"

#include <nlohmann/json.hpp>

#include <cstdio>
#include <fstream>
#include <memory>

namespace bdptref::cli {

namespace {

struct DiagnoseArgs {
    std::string report, suite, signatures, leaveOut;
    double signatureWeight = kSignatureWeight;
    size_t top = 0;
    bool json = false;
};

nlohmann::json readReport(const std::string& path) {
    std::ifstream in(path);
    if (!in) throw InputError("report " + path + ": cannot be read");
    try {
        nlohmann::json j = nlohmann::json::parse(in);
        if (!j.is_object() || !j.contains("scenes") || !j.contains("estimator") || !j.contains("suite"))
            throw InputError("report " + path + ": not a validate report.json (no scenes, estimator or suite)");
        return j;
    } catch (const nlohmann::json::exception& e) {
        throw InputError("report " + path + ": not valid JSON (" + e.what() + ")");
    }
}

int run(const DiagnoseArgs& a) {
    const nlohmann::json report = readReport(a.report);
    Suite suite = loadSuite(a.suite.empty() ? report.at("suite").get<std::string>() : a.suite);
    if (!a.signatures.empty()) suite.signatures = loadSignatures(a.signatures);
    DiagnosisInput in;
    try {
        in = diagnosisInputFromJson(report, suite);
    } catch (const nlohmann::json::exception& e) {
        throw InputError("report " + a.report + ": a scene's result is malformed (" + e.what() + ")");
    }
    in.leaveOut = a.leaveOut;
    in.signatureWeight = a.signatureWeight;
    in.top = a.top;
    if (a.json) {
        const nlohmann::ordered_json out = {{"report", a.report}, {"diagnosis", diagnosisJson(in)},
                                            {"diagnosisPerScene", diagnosisPerSceneJson(in)}};
        std::printf("%s\n", out.dump(1).c_str());
    } else {
        const std::string text = diagnosisText(in);
        std::printf("%s", text.empty() ? "no scene failed: nothing to diagnose\n" : text.c_str());
    }
    return 0;
}

}  // namespace

std::function<int()> addDiagnoseCommand(CLI::App& app) {
    auto a = std::make_shared<DiagnoseArgs>();
    CLI::App* cmd = app.add_subcommand(
        "diagnose",
        "the ranked diagnosis of a saved validate report.json again, without rendering: which term of the "
        "estimator best explains the failing scenes (docs/diagnosis.md)");
    cmd->add_option("report", a->report, "a report.json written by bdptref validate")->required();
    cmd->add_option("--suite", a->suite, "the suite to read the scenes' terms from (default: the one the report names)");
    cmd->add_option("--signatures", a->signatures,
                    "a bug signatures file instead of the suite's (docs/diagnosis.md, \"Bug signatures\")");
    cmd->add_option("--leave-out", a->leaveOut,
                    "ignore this bug's signature (measuring the diagnosis leave-one-out over tools/port_bugs.py)");
    cmd->add_option("--signature-weight", a->signatureWeight,
                    "weight of the best signature's similarity in a term's score (default 4; 0: signatures off)");
    cmd->add_option("--top", a->top,
                    "list the N best terms, however low their confidence (default: up to 5, those under 2% left out after the first 3)")
        ->check(CLI::Range(size_t(1), size_t(1000)));
    cmd->add_flag("--json", a->json, "print {\"diagnosis\": [...], \"diagnosisPerScene\": [...]} instead of text");
    return [a] { return run(*a); };
}

}  // namespace bdptref::cli
