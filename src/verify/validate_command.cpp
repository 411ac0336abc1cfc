// The renderer's command template (docs/validate.md, "Placeholders") and running it: one shell
// command per render, in its own process group so that a timeout or Ctrl-C stops the renderer and
// everything it started.
#include "verify/validate.h"

#include "bdptref/errors.h"

#include <algorithm>
#include <chrono>
#include <csignal>
#include <cstring>
#include <fcntl.h>
#include <sstream>
#include <sys/wait.h>
#include <thread>
#include <unistd.h>

namespace bdptref {

const std::vector<std::string>& commandPlaceholders() {
    static const std::vector<std::string> names{"scene", "out",       "spp", "seed",      "width", "height",
                                                "max_depth", "options", "env_map", "env_scale", "env"};
    return names;
}

namespace {

// 'value' for /bin/sh: single quotes, each ' written as '\''.
std::string shellQuote(const std::string& v) {
    std::string q = "'";
    for (char c : v) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
    return q + "'";
}

// Calls `visit(name)` for every {name} in `command`, `literal(text)` for the text between them.
template <class Visit, class Literal>
void scanTemplate(const std::string& command, Visit visit, Literal literal) {
    size_t i = 0;
    while (i < command.size()) {
        const size_t open = command.find('{', i);
        if (open == std::string::npos) break;
        const size_t close = command.find('}', open);
        if (close == std::string::npos) break;
        literal(command.substr(i, open - i));
        visit(command.substr(open + 1, close - open - 1));
        i = close + 1;
    }
    literal(command.substr(std::min(i, command.size())));
}

}  // namespace

void checkCommandTemplate(const std::string& command) {
    if (command.empty()) throw InputError("--renderer: the command is empty");
    std::vector<std::string> used;
    scanTemplate(command, [&](const std::string& n) { used.push_back(n); }, [](const std::string&) {});
    const auto& known = commandPlaceholders();
    std::string list;
    for (const std::string& k : known) list += (list.empty() ? "{" : ", {") + k + "}";
    for (const std::string& n : used)
        if (std::find(known.begin(), known.end(), n) == known.end())
            throw InputError("--renderer: unknown placeholder {" + n + "} (known: " + list + ")");
    for (const char* required : {"scene", "out", "spp", "seed"})
        if (std::find(used.begin(), used.end(), required) == used.end())
            throw InputError(std::string("--renderer: the command must contain {") + required +
                             "}: validate gives each render its scene, output file, samples per pixel and seed "
                             "(e.g. --renderer 'myrenderer {scene} -o {out} --spp {spp} --seed {seed} --size "
                             "{width}x{height} --max-depth {max_depth}')");
}

std::string expandCommand(const std::string& command, const RenderRequest& r) {
    const SuiteScene& sc = *r.scene;
    std::ostringstream out;
    auto value = [&](const std::string& n) -> std::string {
        if (n == "scene") return shellQuote(sc.scene);
        if (n == "out") return shellQuote(r.output);
        if (n == "spp") return std::to_string(r.spp);
        if (n == "seed") return std::to_string(r.seed);
        if (n == "width") return std::to_string(r.width);
        if (n == "height") return std::to_string(r.height);
        if (n == "max_depth") return std::to_string(sc.maxDepth);
        if (n == "env_map") return sc.envMap.empty() ? std::string() : shellQuote(sc.envMap);
        if (n == "env") return sc.envConstant.empty() ? std::string() : shellQuote(sc.envConstant);
        if (n == "env_scale") {
            std::ostringstream s;
            s.precision(17);
            s << sc.envScale;
            return s.str();
        }
        if (n == "options") {
            std::string o;
            for (const std::string& a : sc.renderOptions()) o += (o.empty() ? "" : " ") + shellQuote(a);
            return o;
        }
        throw InputError("--renderer: unknown placeholder {" + n + "}");
    };
    scanTemplate(command, [&](const std::string& n) { out << value(n); }, [&](const std::string& t) { out << t; });
    return out.str();
}

ProcessResult runShellCommand(const std::string& shellCommand, const std::string& logPath, double timeoutSeconds,
                              const std::function<bool()>& stop) {
    ProcessResult r;
    const int log = ::open(logPath.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
    if (log < 0) throw InputError("cannot write the render log " + logPath + ": " + std::strerror(errno));
    const auto start = std::chrono::steady_clock::now();
    const pid_t pid = ::fork();
    if (pid < 0) {
        ::close(log);
        throw std::runtime_error(std::string("fork failed: ") + std::strerror(errno));
    }
    if (pid == 0) {
        // The child: its own process group (so the group can be stopped), output to the log.
        ::setpgid(0, 0);
        ::dup2(log, STDOUT_FILENO);
        ::dup2(log, STDERR_FILENO);
        const int devnull = ::open("/dev/null", O_RDONLY);
        if (devnull >= 0) ::dup2(devnull, STDIN_FILENO);
        std::signal(SIGINT, SIG_DFL);
        std::signal(SIGTERM, SIG_DFL);
        ::execl("/bin/sh", "sh", "-c", shellCommand.c_str(), static_cast<char*>(nullptr));
        ::_exit(127);
    }
    ::close(log);
    ::setpgid(pid, pid);  // also here: whichever runs first
    auto elapsed = [&] { return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(); };
    int status = 0;
    bool signalled = false;
    double killAt = -1;
    for (;;) {
        const pid_t w = ::waitpid(pid, &status, WNOHANG);
        if (w == pid) break;
        if (w < 0 && errno != EINTR) break;
        if (!signalled && (elapsed() > timeoutSeconds || (stop && stop()))) {
            (elapsed() > timeoutSeconds ? r.timedOut : r.interrupted) = true;
            ::kill(-pid, SIGTERM);
            signalled = true;
            killAt = elapsed() + 3.0;  // a renderer that writes its partial image on SIGTERM gets 3 s
        }
        if (signalled && killAt >= 0 && elapsed() > killAt) {
            ::kill(-pid, SIGKILL);
            killAt = -1;
        }
        std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    r.wallSeconds = elapsed();
    if (WIFEXITED(status)) r.exitCode = WEXITSTATUS(status);
    else if (WIFSIGNALED(status)) r.exitCode = 128 + WTERMSIG(status);
    return r;
}

}  // namespace bdptref
