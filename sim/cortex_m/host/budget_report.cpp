// Runs the Cortex-M budget image (target/budget_main.cpp) under qemu with the insn_count
// plugin (plugin/insn_count.c), turns the instruction counts into per-setpoint figures,
// prints them as a Markdown table and checks the budgets. Counts, never time.
//
//   cortex_m_budget --qemu qemu-system-arm --plugin libpathstream_insn_count.so
//                   --nm arm-none-eabi-nm --board mps2-an386 --label "Cortex-M4"
//                   --image budget.elf [--budget 20]
//                   [--assert narrow:1=22,2=20,3=20,4=20,8=20] [--assert binary:...]
//                   [--assert-marginal] [--assert-stop plain=4480,jerk=40355]
//                   [--assert-shaper 3=MAX,5=MAX,9=MAX]
//                   [--no-legend] [--timeout 60] [--keep DIR]
//
// --assert KIND:A=LIMIT,...: for spans of that kind (narrow, binary, wide) and each listed axis
// count A, tick() per axis per setpoint must be <= LIMIT. The limit is the budget where the
// budget holds and the best figure reached where it does not, so that any regression fails.
// --assert-stop plain=MAX,jerk=MAX: the most instructions one call of plan_stop (plain) or
// plan_jerk_stop (jerk) may execute over the image's seeded states (the best figure reached,
// like the tick limits: a regression fails).
//
// --assert-shaper TAPS=MAX,...: InputShaper::shape with that many taps on every axis may
// execute at most MAX instructions per axis per tick, at every axis count measured.
// Method (docs/cortex-m.md): the address ranges of budget_tick_<A> (SetpointStream::tick
// inlined into an out-of-line function), SetpointStream<A,16>::tick_slow (span start, wide
// spans and the empty queue, called from tick), start_span (called from tick_slow) and
// finish_span come from `nm -S`. The
// plugin counts the instructions executed in each range and snapshots all counters at every
// budget_mark() call, which brackets each phase. For each axis count and span width the
// image runs three phases, (n, S spans), (2n, S), (n, 2S); differences between them cancel
// whatever does not scale with the ticks.
// Exit status: 0 if every asserted figure holds and the counting self-check passes.
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <map>
#include <optional>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

namespace {

struct Options {
    std::string qemu = "qemu-system-arm";
    std::string plugin;
    std::string nm = "arm-none-eabi-nm";
    std::string board = "mps2-an386";
    std::string label = "Cortex-M";
    std::string image;
    std::string keep_dir;
    std::optional<double> budget;
    std::map<std::string, std::map<unsigned, double>> limits;  // kind -> axes -> max per axis
    bool assert_marginal = false;
    std::map<std::string, double> stop_limits;      // plain_stop / jerk_stop -> max per call
    std::map<std::uint64_t, double> shaper_limits;  // taps -> max per axis per tick
    bool legend = true;
    int timeout = 60;
};

[[noreturn]] void die(const std::string& message) {
    std::cerr << "cortex_m_budget: " << message << "\n";
    std::exit(2);
}

std::string shell_quote(const std::string& s) {
    std::string out = "'";
    for (char c : s) {
        if (c == '\'')
            out += "'\\''";
        else
            out += c;
    }
    return out + "'";
}

/// Runs a shell command; returns its stdout (and stderr when merge_stderr) and exit status.
std::pair<std::string, int> run(const std::string& command) {
    FILE* pipe = popen(command.c_str(), "r");
    if (pipe == nullptr) die("cannot run: " + command);
    std::string output;
    char buffer[4096];
    std::size_t n = 0;
    while ((n = std::fread(buffer, 1, sizeof buffer, pipe)) > 0) output.append(buffer, n);
    const int status = pclose(pipe);
    return {output, WIFEXITED(status) ? WEXITSTATUS(status) : 128};
}

std::vector<std::string> lines_of(const std::string& text) {
    std::vector<std::string> lines;
    std::istringstream in(text);
    for (std::string line; std::getline(in, line);) lines.push_back(line);
    return lines;
}

struct Symbol {
    std::uint64_t address = 0;  // Thumb bit cleared
    std::uint64_t size = 0;
    std::string name;  // demangled
};

/// `nm -S -C` of the image: sized text symbols only.
std::vector<Symbol> read_symbols(const Options& o) {
    const auto [text, status] = run(shell_quote(o.nm) + " -S -C " + shell_quote(o.image));
    if (status != 0) die("nm failed on " + o.image);
    std::vector<Symbol> symbols;
    for (const std::string& line : lines_of(text)) {
        std::istringstream in(line);
        std::string addr, size, type;
        if (!(in >> addr >> size >> type)) continue;
        if (type.size() != 1 || std::string("tTwW").find(type[0]) == std::string::npos) continue;
        std::string name;
        std::getline(in, name);
        name.erase(0, name.find_first_not_of(' '));
        Symbol s;
        s.address = std::stoull(addr, nullptr, 16) & ~std::uint64_t{1};
        s.size = std::stoull(size, nullptr, 16);
        s.name = name;
        symbols.push_back(s);
    }
    return symbols;
}

/// The phase lines the image prints: "phase id=3 kind=narrow axes=1 n=64 spans=32 ...".
struct Phase {
    unsigned id = 0;
    std::string kind;
    unsigned axes = 0;
    std::uint64_t n = 0, spans = 0, ticks = 0, calls = 0;
    bool ok = false;
};

std::vector<Phase> parse_phases(const std::string& output) {
    std::vector<Phase> phases;
    for (const std::string& line : lines_of(output)) {
        if (line.rfind("phase ", 0) != 0) continue;
        std::map<std::string, std::string> kv;
        std::istringstream in(line.substr(6));
        for (std::string field; in >> field;) {
            const auto eq = field.find('=');
            if (eq != std::string::npos) kv[field.substr(0, eq)] = field.substr(eq + 1);
        }
        Phase p;
        p.id = static_cast<unsigned>(std::stoul(kv.at("id")));
        p.kind = kv.at("kind");
        p.axes = static_cast<unsigned>(std::stoul(kv.at("axes")));
        p.n = std::stoull(kv.at("n"));
        p.spans = std::stoull(kv.at("spans"));
        p.ticks = std::stoull(kv.at("ticks"));
        p.calls = std::stoull(kv.at("calls"));
        p.ok = kv.at("ok") == "1";
        phases.push_back(p);
    }
    return phases;
}

/// Range roles inside tick()'s world, per axis count.
enum class Role { kTick, kSlowPath, kFinishSpan, kCalibrate };

struct Range {
    Symbol symbol;
    Role role;
    unsigned axes;
};

std::string fmt(double v, int decimals = 2) {
    char buffer[64];
    std::snprintf(buffer, sizeof buffer, "%.*f", decimals, v);
    return buffer;
}

Options parse_options(int argc, char** argv) {
    Options o;
    for (int i = 1; i < argc; ++i) {
        const std::string arg = argv[i];
        auto value = [&]() -> std::string {
            if (i + 1 >= argc) die("missing value after " + arg);
            return argv[++i];
        };
        if (arg == "--qemu")
            o.qemu = value();
        else if (arg == "--plugin")
            o.plugin = value();
        else if (arg == "--nm")
            o.nm = value();
        else if (arg == "--board")
            o.board = value();
        else if (arg == "--label")
            o.label = value();
        else if (arg == "--image")
            o.image = value();
        else if (arg == "--keep")
            o.keep_dir = value();
        else if (arg == "--budget")
            o.budget = std::stod(value());
        else if (arg == "--timeout")
            o.timeout = std::stoi(value());
        else if (arg == "--assert-marginal")
            o.assert_marginal = true;
        else if (arg == "--no-legend")
            o.legend = false;
        else if (arg == "--assert") {
            const std::string spec = value();
            const auto colon = spec.find(':');
            if (colon == std::string::npos) die("--assert wants KIND:A=LIMIT,...: " + spec);
            auto& limits = o.limits[spec.substr(0, colon)];
            std::istringstream in(spec.substr(colon + 1));
            for (std::string item; std::getline(in, item, ',');) {
                const auto eq = item.find('=');
                if (eq == std::string::npos) die("--assert wants KIND:A=LIMIT,...: " + spec);
                limits[static_cast<unsigned>(std::stoul(item.substr(0, eq)))] =
                    std::stod(item.substr(eq + 1));
            }
        } else if (arg == "--assert-stop") {
            const std::string spec = value();
            std::istringstream in(spec);
            for (std::string item; std::getline(in, item, ',');) {
                const auto eq = item.find('=');
                const std::string kind = eq == std::string::npos ? "" : item.substr(0, eq);
                if (kind != "plain" && kind != "jerk")
                    die("--assert-stop wants plain=MAX,jerk=MAX: " + spec);
                o.stop_limits[kind + "_stop"] = std::stod(item.substr(eq + 1));
            }
        } else if (arg == "--assert-shaper") {
            const std::string spec = value();
            std::istringstream in(spec);
            for (std::string item; std::getline(in, item, ',');) {
                const auto eq = item.find('=');
                if (eq == std::string::npos) die("--assert-shaper wants TAPS=MAX,...: " + spec);
                o.shaper_limits[std::stoull(item.substr(0, eq))] = std::stod(item.substr(eq + 1));
            }
        } else
            die("unknown argument " + arg);
    }
    if (o.plugin.empty() || o.image.empty()) die("--plugin and --image are required");
    return o;
}

}  // namespace

int main(int argc, char** argv) {
    const Options o = parse_options(argc, argv);
    const std::vector<Symbol> symbols = read_symbols(o);

    // Ranges: every symbol of interest becomes one plugin range.
    std::vector<Range> ranges;
    std::optional<std::uint64_t> mark;
    const std::regex tick_re(R"(^budget_tick_(\d+)(\..*| .*)?$)");
    const std::regex member_re(
        R"(SetpointStream<(\d+)u?l?, 16u?l?>::(tick_slow|start_span|finish_span)\()");
    for (const Symbol& s : symbols) {
        std::smatch m;
        if (s.name == "budget_mark")
            mark = s.address;
        else if (s.name == "budget_calibrate")
            ranges.push_back({s, Role::kCalibrate, 0});
        else if (std::regex_match(s.name, m, tick_re)) {
            ranges.push_back({s, Role::kTick, static_cast<unsigned>(std::stoul(m[1]))});
        } else if (std::regex_search(s.name, m, member_re)) {
            const std::string f = m[2];
            const Role role = f == "finish_span" ? Role::kFinishSpan : Role::kSlowPath;
            ranges.push_back({s, role, static_cast<unsigned>(std::stoul(m[1]))});
        }
    }
    if (!mark) die("budget_mark not found in " + o.image);
    if (ranges.size() > 64) die("too many ranges for the plugin");

    // Run qemu once with the plugin.
    std::string dir = o.keep_dir;
    if (dir.empty()) {
        char templ[] = "/tmp/cortex_m_budget.XXXXXX";
        if (mkdtemp(templ) == nullptr) die("mkdtemp failed");
        dir = templ;
    } else {
        (void)run("mkdir -p " + shell_quote(dir));
    }
    const std::string counts_path = dir + "/insn_count.txt";
    std::string plugin_arg = o.plugin + ",mark=0x" + [&] {
        char b[32];
        std::snprintf(b, sizeof b, "%llx", static_cast<unsigned long long>(*mark));
        return std::string(b);
    }();
    for (const Range& r : ranges) {
        char b[64];
        std::snprintf(b, sizeof b, ",range=0x%llx:0x%llx",
                      static_cast<unsigned long long>(r.symbol.address),
                      static_cast<unsigned long long>(r.symbol.address + r.symbol.size));
        plugin_arg += b;
    }
    plugin_arg += ",out=" + counts_path;
    const std::string command =
        "timeout " + std::to_string(o.timeout) + " " + shell_quote(o.qemu) + " -M " +
        shell_quote(o.board) +
        " -semihosting-config enable=on,target=native -nographic -monitor none -serial none"
        " -kernel " +
        shell_quote(o.image) + " -plugin " + shell_quote(plugin_arg) + " 2>&1";
    const auto [output, status] = run(command);
    if (!o.keep_dir.empty()) {
        std::ofstream(dir + "/qemu_output.txt") << command << "\n" << output;
    }
    if (status != 0 || output.find("budget done") == std::string::npos) {
        std::cerr << command << "\n" << output;
        die("the budget image failed (exit status " + std::to_string(status) + ")");
    }

    // Plugin report: marks (snapshots of total and every range counter).
    std::vector<std::vector<std::uint64_t>> marks;
    {
        std::ifstream in(counts_path);
        if (!in) die("plugin wrote no report at " + counts_path);
        for (std::string line; std::getline(in, line);) {
            std::istringstream fields(line);
            std::string tag, what;
            fields >> tag >> what;
            if (what != "mark") continue;
            unsigned index = 0;
            fields >> index;
            std::vector<std::uint64_t> row;
            for (std::uint64_t v; fields >> v;) row.push_back(v);
            if (index != marks.size() || row.size() != 1 + ranges.size()) die("bad plugin report");
            marks.push_back(row);
        }
    }
    if (o.keep_dir.empty()) {
        std::remove(counts_path.c_str());
        rmdir(dir.c_str());
    }

    const std::vector<Phase> phases = parse_phases(output);
    bool failed = false;
    auto fail = [&](const std::string& why) {
        std::cout << "FAIL: " << why << "\n";
        failed = true;
    };
    if (output.find("budget done") == std::string::npos ||
        output.find("FAILED") != std::string::npos) {
        fail("the image reported a failed phase");
    }
    if (marks.size() != 2 * phases.size()) fail("marks do not match phases");

    // Counts of a phase: total, and the sum over ranges selected by a predicate.
    auto delta = [&](const Phase& p, std::size_t column) {
        return static_cast<double>(marks.at(2 * p.id + 1).at(column) -
                                   marks.at(2 * p.id).at(column));
    };
    auto range_sum = [&](const Phase& p, auto predicate) {
        double sum = 0;
        for (std::size_t r = 0; r < ranges.size(); ++r) {
            if (predicate(ranges[r])) sum += delta(p, 1 + r);
        }
        return sum;
    };

    std::cout << "\n## " << o.label << ": SetpointStream<A, 16>, executed instructions (qemu -M "
              << o.board << ", TCG plugin counts)\n\n";

    // Self-check of the counting method: the calibration loop's exact count.
    for (const Phase& p : phases) {
        if (p.kind != "calibrate") continue;
        const double counted =
            range_sum(p, [](const Range& r) { return r.role == Role::kCalibrate; });
        const double expected = 2.0 * static_cast<double>(p.n) + 1.0;
        std::cout << "Counting self-check: budget_calibrate(" << p.n << ") executed "
                  << fmt(counted, 0) << " instructions, expected " << fmt(expected, 0) << " ("
                  << (counted == expected ? "exact" : "MISMATCH") << ")\n\n";
        if (counted != expected) fail("plugin calibration count is not exact");
    }

    struct Row {
        std::string kind;
        std::uint64_t n = 0;
        unsigned axes = 0;
        double steady = 0, consumer = 0, whole = 0, switch_per_span = 0, push_per_span = 0;
    };
    std::vector<Row> rows;
    const char* const kinds[] = {"narrow", "binary", "wide"};
    for (const std::string kind : kinds) {
        std::map<unsigned, std::vector<Phase>> by_axes;
        std::map<unsigned, Phase> push_of;
        for (const Phase& p : phases) {
            if (p.kind == kind) by_axes[p.axes].push_back(p);
            if (p.kind == "push_" + kind) push_of[p.axes] = p;
            if (!p.ok) fail("phase " + std::to_string(p.id) + " (" + p.kind + ") not ok");
        }
        for (const auto& [axes, ps] : by_axes) {
            if (ps.size() != 3 || push_of.count(axes) == 0)
                die("expected three phases and a push phase per axis count");
            const Phase &p1 = ps[0], &p2 = ps[1], &p3 = ps[2];  // (n,S) (2n,S) (n,2S)
            const unsigned a = axes;
            auto in_tick = [a](const Range& r) {
                return r.axes == a && (r.role == Role::kTick || r.role == Role::kSlowPath);
            };
            auto in_consumer = [a](const Range& r) {
                return r.axes == a && r.role != Role::kCalibrate;
            };
            bool have_tick = false;
            for (const Range& r : ranges) have_tick |= r.axes == a && r.role == Role::kTick;
            if (!have_tick) die("no budget_tick_" + std::to_string(a) + " symbol");
            if (p2.spans != p1.spans || p2.n != 2 * p1.n || p3.n != p1.n ||
                p3.spans != 2 * p1.spans) {
                die("unexpected phase layout for " + kind);
            }
            Row row;
            row.kind = kind;
            row.n = p1.n;
            row.axes = a;
            const double t1 = static_cast<double>(p1.ticks);
            row.steady = (range_sum(p2, in_tick) - range_sum(p1, in_tick)) /
                         static_cast<double>(p2.ticks - p1.ticks);
            row.consumer = range_sum(p1, in_consumer) / t1;
            row.whole = (delta(p3, 0) - delta(p1, 0)) / static_cast<double>(p3.ticks - p1.ticks);
            // (n, 2S) has S more spans and S n more ticks than (n, S): what it executes beyond
            // those ticks' steady cost is the span switches, whatever functions they live in.
            row.switch_per_span = (range_sum(p3, in_consumer) - range_sum(p1, in_consumer) -
                                   row.steady * static_cast<double>(p3.ticks - p1.ticks)) /
                                  static_cast<double>(p3.spans - p1.spans);
            const Phase& push = push_of.at(a);
            row.push_per_span = delta(push, 0) / static_cast<double>(push.calls);
            rows.push_back(row);
        }
    }

    // Marginal cost per extra axis, and a least-squares line c + m * A per width.
    std::map<std::string, std::pair<double, double>> fit;
    for (const char* kind : kinds) {
        double sx = 0, sy = 0, sxx = 0, sxy = 0, count = 0;
        for (const Row& r : rows) {
            if (r.kind != kind) continue;
            sx += r.axes;
            sy += r.steady;
            sxx += double(r.axes) * r.axes;
            sxy += r.axes * r.steady;
            count += 1;
        }
        if (count >= 2) {
            const double m = (count * sxy - sx * sy) / (count * sxx - sx * sx);
            fit[kind] = {(sy - m * sx) / count, m};
        }
    }

    const std::string budget_text = o.budget ? fmt(*o.budget, 0) : "-";
    std::cout
        << "| spans | axes A | tick() per tick | per axis per setpoint | marginal per extra axis"
           " | amortized tick() incl. span switches, per axis | whole run incl. push(), per axis"
           " | span switch per span | push() per span | <= "
        << budget_text << " per axis |\n";
    std::cout << "|---|---|---|---|---|---|---|---|---|---|\n";
    for (std::size_t i = 0; i < rows.size(); ++i) {
        const Row& r = rows[i];
        std::string marginal = "-";
        if (i > 0 && rows[i - 1].kind == r.kind) {
            const double m = (r.steady - rows[i - 1].steady) / (r.axes - rows[i - 1].axes);
            marginal = fmt(m);
            if (o.assert_marginal && r.kind == "narrow" && o.budget && m > *o.budget) {
                fail("narrow marginal cost per axis " + fmt(m) + " > " + budget_text);
            }
        }
        const double per_axis = r.steady / r.axes;
        std::string verdict = "-";
        if (o.budget) {
            verdict = per_axis <= *o.budget ? "yes" : "no, by " + fmt(per_axis - *o.budget);
        }
        if (const auto kind_limits = o.limits.find(r.kind); kind_limits != o.limits.end()) {
            if (const auto limit = kind_limits->second.find(r.axes);
                limit != kind_limits->second.end()) {
                verdict += " (asserted <= " + fmt(limit->second) + ")";
                // The printed figure (2 decimals) is what is compared, so that a limit copied
                // from a table holds exactly.
                if (std::stod(fmt(per_axis)) > limit->second) {
                    fail(r.kind + ", A = " + std::to_string(r.axes) + ": " + fmt(per_axis) +
                         " instructions per axis per setpoint > " + fmt(limit->second));
                }
            }
        }
        std::cout << "| " << r.kind << " n=" << r.n << " | " << r.axes << " | " << fmt(r.steady)
                  << " | " << fmt(per_axis) << " | " << marginal << " | "
                  << fmt(r.consumer / r.axes) << " | " << fmt(r.whole / r.axes) << " | "
                  << fmt(r.switch_per_span, 1) << " | " << fmt(r.push_per_span, 0) << " | "
                  << verdict << " |\n";
    }
    std::cout << "\n";
    for (const auto& [kind, cm] : fit) {
        std::cout << "Least-squares fit, " << kind << ": tick() = " << fmt(cm.first, 1) << " + "
                  << fmt(cm.second, 2) << " * A instructions per tick\n";
    }

    for (const Phase& p : phases) {
        if (p.kind != "horner") continue;
        const double per_call = delta(p, 0) / static_cast<double>(p.calls);
        std::cout << "Horner evaluate_at, n = " << p.n << ": " << fmt(per_call, 1)
                  << " instructions per call (whole call, 128-bit arithmetic and libgcc helpers"
                     " included)\n";
    }
    // The device's controlled stop, one call per phase: mean and largest per call.
    for (const char* kind : {"plain_stop", "jerk_stop"}) {
        double sum = 0, most = 0;
        std::size_t count = 0;
        unsigned axes = 0;
        for (const Phase& p : phases) {
            if (p.kind != kind) continue;
            sum += delta(p, 0);
            most = std::max(most, delta(p, 0));
            axes = p.axes;
            ++count;
        }
        if (count == 0) continue;
        std::cout << (std::string(kind) == "jerk_stop" ? "plan_jerk_stop" : "plan_stop") << "<"
                  << axes << ">, the controlled stop planned in the tick that takes a hold ("
                  << count << " seeded states): " << fmt(sum / static_cast<double>(count), 0)
                  << " instructions per call on"
                  << " average, " << fmt(most, 0) << " at most";
        if (const auto limit = o.stop_limits.find(kind); limit != o.stop_limits.end()) {
            std::cout << " (asserted <= " << fmt(limit->second, 0) << ")";
            if (most > limit->second) {
                std::cout << "\n";
                fail(std::string(kind) + ": " + fmt(most, 0) + " instructions in one call, over " +
                     fmt(limit->second, 0));
                continue;
            }
        }
        std::cout << "\n";
    }
    // The whole device: phases (n, S) and (2n, S) of the same axis count; their difference is
    // S n steady ticks of MotionDevice::tick and the driver loop's check per tick.
    std::map<unsigned, std::vector<Phase>> device_phases;
    for (const Phase& p : phases) {
        if (p.kind == "device") device_phases[p.axes].push_back(p);
    }
    for (const auto& [axes, list] : device_phases) {
        if (list.size() != 2 || list[1].n != 2 * list[0].n || list[1].spans != list[0].spans) {
            fail("device phases are not (n, S) and (2n, S)");
            continue;
        }
        const double per_tick = (delta(list[1], 0) - delta(list[0], 0)) /
                                static_cast<double>(list[0].spans * list[0].n);
        const double whole = delta(list[0], 0) / static_cast<double>(list[0].ticks);
        std::cout << "MotionDevice<" << axes
                  << ", 16>::tick in steady state, narrow spans n = " << list[0].n << ": "
                  << fmt(per_tick) << " instructions per tick (" << fmt(per_tick / axes)
                  << " per axis; the status publication, the mailbox"
                     " reads and SetpointStream::tick included); whole run with batches decoded"
                     " and checked: "
                  << fmt(whole) << " per tick\n";
    }
    // The input shaper: phases (taps, T ticks) and (taps, 2T ticks) per axis count; their
    // difference is T steady calls of shape() plus the driver loop's ramp.
    std::map<std::pair<std::uint64_t, unsigned>, std::vector<Phase>> shaper_phases;
    for (const Phase& p : phases) {
        if (p.kind != "shaper") continue;
        if (!p.ok) fail("phase " + std::to_string(p.id) + " (shaper) not ok");
        shaper_phases[{p.n, p.axes}].push_back(p);
    }
    if (!shaper_phases.empty()) {
        std::cout << "\nInputShaper<A, 256>::shape, steady state (instructions):\n\n"
                     "| taps | A | per tick | per axis per tick |\n|---|---|---|---|\n";
    }
    for (const auto& [key, list] : shaper_phases) {
        const auto [taps, axes] = key;
        if (list.size() != 2 || list[1].ticks != 2 * list[0].ticks) {
            fail("shaper phases are not (taps, T) and (taps, 2T)");
            continue;
        }
        const double per_tick =
            (delta(list[1], 0) - delta(list[0], 0)) / static_cast<double>(list[0].ticks);
        const double per_axis = per_tick / axes;
        std::cout << "| " << taps << " | " << axes << " | " << fmt(per_tick) << " | "
                  << fmt(per_axis) << " |\n";
        if (const auto limit = o.shaper_limits.find(taps);
            limit != o.shaper_limits.end() && per_axis > limit->second) {
            fail("shaper, " + std::to_string(taps) + " taps, A = " + std::to_string(axes) + ": " +
                 fmt(per_axis) + " per axis per tick, over " + fmt(limit->second));
        }
    }
    if (!o.shaper_limits.empty()) {
        std::cout << "Asserted: shaper per axis per tick <=";
        bool first = true;
        for (const auto& [taps, limit] : o.shaper_limits) {
            std::cout << (first ? " " : ", ") << fmt(limit) << " with " << taps << " taps";
            first = false;
        }
        std::cout << "\n";
    }
    if (o.legend)
        std::cout
            << "\nColumns (docs/cortex-m.md):\n"
               "- tick() per tick: steady state, instructions executed inside tick() (and"
               " tick_slow for wide spans) per tick, from two runs with the same spans and n vs"
               " 2n ticks each; the setpoint output (exact, rounded) included.\n"
               "- spans: narrow, 32-bit remainders and D not a power of two (the step with"
               " its correction by K); binary, D a power of two (no correction); wide, 64-bit"
               " remainders.\n"
               "- per axis per setpoint: that divided by A; the budget applies to it.\n"
               "- marginal: extra instructions per tick for each added axis.\n"
               "- amortized: everything tick() executes (tick_slow, start_span, finish_span"
               " included) over a run of spans of n ticks, per tick, per axis.\n"
               "- whole run: difference of runs with S and 2S spans of n ticks: the driver"
               " loop, push() (validation, prepare_span) and tick(), per tick, per axis.\n";
    for (const auto& [kind, limits] : o.limits) {
        std::cout << "Asserted: " << kind << " per axis per setpoint <=";
        bool first = true;
        for (const auto& [a, limit] : limits) {
            std::cout << (first ? " " : ", ") << fmt(limit) << " at A = " << a;
            first = false;
        }
        std::cout << "\n";
    }
    if (o.assert_marginal && o.budget) {
        std::cout << "Asserted: narrow marginal cost per axis <= " << budget_text << "\n";
    }
    std::cout << (failed ? "RESULT: FAIL\n" : "RESULT: ok\n");
    return failed ? 1 : 0;
}
