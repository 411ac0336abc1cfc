// The renderer's command template (docs/validate.md, "What your renderer must do") and running it:
// one shell command per render (or per scene, with {seeds}), in its own process group so that a timeout or Ctrl-C stops the renderer and
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
    static const std::vector<std::string> names{"scene",   "out",     "spp",       "seed",      "seeds", "width",
                                                "height",  "max_depth", "options", "env_map", "env_scale", "env"};
    return names;
}

namespace {

// 'value' for /bin/sh: single quotes, each ' written as '\''.
std::string shellQuote(const std::string& v) {
    std::string q = "'";
    for (char c : v) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
    return q + "'";
}

// A command template cut at its placeholders: `literal`, then {name} or {name:text}.
struct TemplatePart {
    std::string literal;       // the text before the placeholder
    bool placeholder = false;  // false: the template's tail (literal only)
    std::string name;
    bool conditional = false;  // {name:text}: text with % for the value, nothing when the value is empty
    std::string text;
};

// Cuts the template; a { without its }, a { inside a placeholder or a {name:text} without % is an
// error, since each would otherwise run a command other than the one the user meant.
std::vector<TemplatePart> parseTemplate(const std::string& command) {
    std::vector<TemplatePart> parts;
    size_t i = 0;
    for (;;) {
        const size_t open = command.find('{', i);
        if (open == std::string::npos) break;
        const size_t close = command.find('}', open);
        const size_t nested = command.find('{', open + 1);
        if (close == std::string::npos)
            throw InputError("--renderer: '{' at character " + std::to_string(open + 1) +
                             " has no closing '}' (placeholders are {name} or {name:text with %})");
        if (nested < close)
            throw InputError("--renderer: '{' inside the placeholder at character " + std::to_string(open + 1) +
                             " (placeholders do not nest: {name} or {name:text with %})");
        TemplatePart part;
        part.placeholder = true;
        part.literal = command.substr(i, open - i);
        const std::string inside = command.substr(open + 1, close - open - 1);
        const size_t colon = inside.find(':');
        part.name = inside.substr(0, colon);
        if (colon != std::string::npos) {
            part.conditional = true;
            part.text = inside.substr(colon + 1);
            if (part.text.find('%') == std::string::npos)
                throw InputError("--renderer: {" + inside + "} has no %: in {" + part.name +
                                 ":text} the % marks where the value goes (e.g. {env_map:--envmap %})");
        }
        parts.push_back(part);
        i = close + 1;
    }
    TemplatePart tail;
    tail.literal = command.substr(std::min(i, command.size()));
    parts.push_back(tail);
    return parts;
}

bool uses(const std::vector<TemplatePart>& parts, const char* name) {
    return std::any_of(parts.begin(), parts.end(), [&](const TemplatePart& p) { return p.placeholder && p.name == name; });
}

// {name:text} with a value: text with each % replaced by it (%% is a literal %).
std::string fillConditional(const std::string& text, const std::string& value) {
    std::string out;
    for (size_t k = 0; k < text.size(); ++k) {
        if (text[k] != '%') out += text[k];
        else if (k + 1 < text.size() && text[k + 1] == '%') out += '%', ++k;
        else out += value;
    }
    return out;
}

// The placeholder's value as it goes into the shell command ("" when the scene has none).
std::string placeholderValue(const std::string& n, const RenderRequest& r) {
    const SuiteScene& sc = *r.scene;
    auto decimal = [](double v) {
        std::ostringstream s;
        s.precision(17);
        s << v;
        return s.str();
    };
    if (n == "scene") return shellQuote(sc.scene);
    if (n == "out") return shellQuote(r.output);
    if (n == "spp") return std::to_string(r.spp);
    if (n == "seed") return std::to_string(r.seed);
    if (n == "seeds") {
        std::string list;
        for (uint32_t s : r.seeds) list += (list.empty() ? "" : ",") + std::to_string(s);
        return list;
    }
    if (n == "width") return std::to_string(r.width);
    if (n == "height") return std::to_string(r.height);
    if (n == "max_depth") return std::to_string(sc.maxDepth);
    if (n == "env_map") return sc.envMap.empty() ? std::string() : shellQuote(sc.envMap);
    if (n == "env") return sc.envConstant.empty() ? std::string() : shellQuote(sc.envConstant);
    if (n == "env_scale") return sc.envMap.empty() ? std::string() : decimal(sc.envScale);  // a scale of no map
    if (n == "options") {
        std::string o;
        for (const std::string& a : sc.renderOptions()) o += (o.empty() ? "" : " ") + shellQuote(a);
        return o;
    }
    throw InputError("--renderer: unknown placeholder {" + n + "}");
}

}  // namespace

void checkCommandTemplate(const std::string& command) {
    if (command.empty()) throw InputError("--renderer: the command is empty");
    const std::vector<TemplatePart> parts = parseTemplate(command);
    const auto& known = commandPlaceholders();
    std::string list;
    for (const std::string& k : known) list += (list.empty() ? "{" : ", {") + k + "}";
    for (const TemplatePart& p : parts)
        if (p.placeholder && std::find(known.begin(), known.end(), p.name) == known.end())
            throw InputError("--renderer: unknown placeholder {" + p.name + "} (known: " + list +
                                 "; each also as {name:text with %}, which is empty when the value is)");
    for (const char* required : {"scene", "out", "spp"})
        if (!uses(parts, required))
            throw InputError(std::string("--renderer: the command must contain {") + required +
                             "}: validate gives each render its scene, output file, samples per pixel and seed "
                             "(e.g. --renderer 'myrenderer {scene} -o {out} --spp {spp} --seed {seed} --size "
                             "{width}x{height} --max-depth {max_depth}')");
    const bool one = uses(parts, "seed"), many = uses(parts, "seeds");
    if (!one && !many)
        throw InputError("--renderer: the command must contain {seed} (one render per process) or {seeds} (all "
                         "renders of a scene in one process, {out} then holds {seed}): without a seed every render "
                         "would be the same");
    if (one && many)
        throw InputError("--renderer: use {seed} or {seeds}, not both: with {seeds} the renderer is given every "
                         "seed of a scene at once and writes {out} with {seed} replaced by each (docs/validate.md)");
}

bool commandTakesSeedList(const std::string& command) { return uses(parseTemplate(command), "seeds"); }

std::string outputForSeed(const std::string& pattern, uint32_t seed) {
    std::string out = pattern;
    const std::string key = "{seed}", value = std::to_string(seed);
    for (size_t at = out.find(key); at != std::string::npos; at = out.find(key, at + value.size()))
        out.replace(at, key.size(), value);
    return out;
}

std::string expandCommand(const std::string& command, const RenderRequest& r) {
    std::string out;
    for (const TemplatePart& p : parseTemplate(command)) {
        out += p.literal;
        if (!p.placeholder) continue;
        const std::string v = placeholderValue(p.name, r);
        out += !p.conditional ? v : v.empty() ? std::string() : fillConditional(p.text, v);
    }
    return out;
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
