// The `bdptref` command. Exit codes: 0 success, 1 internal error, 2 unusable input (bad scene,
// bad option, unwritable output, a request too large for this machine's memory), 130/143
// interrupted (the partial image was still written).
#include "bdptref/errors.h"
#include "bdptref/version.h"
#include "cli/commands.h"

#include <cstdio>
#include <exception>
#include <new>
#include <stdexcept>

int main(int argc, char** argv) {
    CLI::App app{"bdptref " BDPTREF_VERSION
                 " - a CPU reference renderer: bidirectional path tracing with multiple importance sampling.\n"
                 "Run 'bdptref <command> --help' for the options of a command."};
    app.set_version_flag("--version", "bdptref " BDPTREF_VERSION " (" BDPTREF_GIT_REVISION ")");
    app.require_subcommand(1);
    const auto render = bdptref::cli::addRenderCommand(app);
    const auto info = bdptref::cli::addInfoCommand(app);
    const auto compare = bdptref::cli::addCompareCommand(app);
    const auto trace = bdptref::cli::addTraceCommand(app);
    const auto mis = bdptref::cli::addMisCommand(app);
    const auto merge = bdptref::cli::addMergeCommand(app);
    const auto validate = bdptref::cli::addValidateCommand(app);
    const auto diagnose = bdptref::cli::addDiagnoseCommand(app);
    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        const int code = app.exit(e);
        return code == 0 ? 0 : 2;  // --help and --version exit 0; any invalid option is input error 2
    }
    try {
        if (app.got_subcommand("render")) return render();
        if (app.got_subcommand("info")) return info();
        if (app.got_subcommand("compare")) return compare();
        if (app.got_subcommand("trace")) return trace();
        if (app.got_subcommand("mis")) return mis();
        if (app.got_subcommand("merge")) return merge();
        if (app.got_subcommand("validate")) return validate();
        if (app.got_subcommand("diagnose")) return diagnose();
        return 2;
    } catch (const bdptref::InputError& e) {
        std::fprintf(stderr, "bdptref: error: %s\n", e.what());
        return 2;
    } catch (const std::bad_alloc& e) {
        // Requests are sized up front (render refuses what cannot fit), so this is an input that
        // needs more memory than this machine gives: the user's to change, not a bug.
        std::fprintf(stderr, "bdptref: error: out of memory: %s (the input needs more memory than is available; "
                             "try a smaller image, a --crop, fewer --strategies layers or a lower --max-depth)\n", e.what());
        return 2;
    } catch (const std::length_error& e) {
        std::fprintf(stderr, "bdptref: error: out of memory: a buffer larger than any allocation (%s)\n", e.what());
        return 2;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "bdptref: internal error: %s\n", e.what());
        return 1;
    }
}
