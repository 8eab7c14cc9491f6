// docs/modbus.md against the device: a host is written from that page alone, so what it states
// about the register map must be what the device does. The numbers come from the firmware
// core's own constants and functions (modbus_map.hpp, modbus_register_map.hpp, status.hpp) or
// from the register map itself; none is copied here. Each failure names the doc line and says
// what the device says instead.
#include <algorithm>
#include <bit>
#include <catch2/catch.hpp>
#include <cstddef>
#include <cstdint>
#include <fstream>
#include <map>
#include <optional>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "pathstream/device/batch_crc.hpp"
#include "pathstream/device/modbus_map.hpp"
#include "pathstream/device/modbus_register_map.hpp"
#include "pathstream/span.hpp"
#include "pathstream/status.hpp"

using namespace pathstream;

namespace {

namespace mb = device::modbus;
namespace st = device::modbus::status;
using Ex = mb::Exception;

// The worked example of the page is a 2-axis one (docs/device.md, "Wire span"); the test runs
// it on a device of that many axes.
constexpr unsigned kExampleAxes = 2;
using ExampleDevice = device::MotionDevice<kExampleAxes, 16>;
using ExampleMap = device::ModbusRegisterMap<kExampleAxes, 16>;

// The device's own Status -> exception mapping, not a copy of it.
Ex exception_for(Status s) {
    return ExampleMap::exception_for(s);
}

struct DocLine {
    int number = 0;  // 1-based
    std::string text;
};

// The page whole (lines joined by '\n'), its lines, and where each line starts in the whole.
struct Doc {
    std::string text;
    std::vector<DocLine> lines;
    std::vector<std::size_t> starts;
};

const Doc& doc() {
    static const Doc d = [] {
        Doc r;
        std::ifstream in(std::string(PATHSTREAM_SOURCE_DIR) + "/docs/modbus.md");
        std::string l;
        for (int n = 1; std::getline(in, l); ++n) {
            r.starts.push_back(r.text.size());
            r.text += l + '\n';
            r.lines.push_back({n, l});
        }
        return r;
    }();
    return d;
}

std::string where(const DocLine& l) {
    return "docs/modbus.md:" + std::to_string(l.number) + ": " + l.text;
}

// A number as the page writes it: digit groups with commas, a minus sign (U+2212) or '-'.
long long number(std::string s) {
    std::string t;
    bool negative = false;
    if (s.rfind("−", 0) == 0) {
        negative = true;
        s = s.substr(std::string("−").size());
    } else if (!s.empty() && s[0] == '-') {
        negative = true;
        s = s.substr(1);
    }
    for (char c : s)
        if (c != ',') t += c;
    const long long v = std::stoll(t);
    return negative ? -v : v;
}

// A pattern for running text: any space may be a line break or several spaces.
std::string prose(const std::string& pattern) {
    std::string out;
    for (char c : pattern) out += c == ' ' ? std::string("\\s+") : std::string(1, c);
    return out;
}

struct Found {
    DocLine line;           // the line the match starts on
    std::size_t last_line;  // index of the line it ends on
    std::smatch m;          // into doc().text, which lives as long as the program
};

// Every match of `pattern` (ECMAScript, multiline: ^ and $ at line ends) in the lines
// [from, to) of the page.
std::vector<Found> find_all(const std::string& pattern, std::size_t from = 0,
                            std::size_t to = SIZE_MAX) {
    const std::regex re(pattern, std::regex::ECMAScript | std::regex::multiline);
    const Doc& d = doc();
    std::vector<Found> out;
    if (from >= d.lines.size()) return out;
    const std::size_t begin = d.starts[from],
                      end = to < d.lines.size() ? d.starts[to] : d.text.size();
    for (auto it = std::sregex_iterator(d.text.begin() + static_cast<std::ptrdiff_t>(begin),
                                        d.text.begin() + static_cast<std::ptrdiff_t>(end), re);
         it != std::sregex_iterator(); ++it) {
        const auto line_of = [&](std::size_t at) {
            return static_cast<std::size_t>(std::upper_bound(d.starts.begin(), d.starts.end(), at) -
                                            d.starts.begin()) -
                   1;
        };
        const std::size_t at = begin + static_cast<std::size_t>(it->position(0));
        const std::size_t length = static_cast<std::size_t>(it->length(0));
        out.push_back({d.lines[line_of(at)], line_of(length == 0 ? at : at + length - 1), *it});
    }
    return out;
}

// The first match of `pattern`; a failed check naming `what` when the page has none.
std::optional<Found> find_one(const std::string& pattern, const std::string& what,
                              std::size_t from = 0, std::size_t to = SIZE_MAX) {
    auto all = find_all(pattern, from, to);
    if (all.empty()) {
        FAIL_CHECK("docs/modbus.md no longer states "
                   << what << " in the form the test reads (text matching /" << pattern << "/)");
        return std::nullopt;
    }
    return all.front();
}

// The section from the heading matching `pattern` to the next heading of level 2, as line
// indices [first, end).
std::pair<std::size_t, std::size_t> section(const std::string& pattern) {
    const std::regex re(pattern);
    const auto& lines = doc().lines;
    std::size_t from = 0;
    while (from < lines.size() && !std::regex_search(lines[from].text, re)) ++from;
    std::size_t to = from + 1;
    while (to < lines.size() && lines[to].text.rfind("## ", 0) != 0) ++to;
    return {from, to};
}

// An exception code as the page writes it: two digits.
std::string code(int exception) {
    return (exception < 10 ? "0" : "") + std::to_string(exception);
}

void check_value(const DocLine& l, long long doc_value, long long device_value,
                 const std::string& what) {
    INFO(where(l) << "\n  the page says " << what << " is " << doc_value << ", the device says "
                  << device_value);
    CHECK(doc_value == device_value);
}

// The 4-digit hex words of the first fenced code block after the match `after` (before the
// next heading).
std::vector<std::uint16_t> code_block_words(const Found& after) {
    std::vector<std::uint16_t> words;
    const auto& lines = doc().lines;
    std::size_t i = after.last_line + 1;
    while (i < lines.size() && lines[i].text.rfind("```", 0) != 0) {
        if (lines[i].text.rfind("#", 0) == 0) return words;
        ++i;
    }
    const std::regex word("\\b[0-9A-Fa-f]{4}\\b");
    for (++i; i < lines.size() && lines[i].text.rfind("```", 0) != 0; ++i) {
        const std::string& t = lines[i].text;
        for (auto it = std::sregex_iterator(t.begin(), t.end(), word); it != std::sregex_iterator();
             ++it)
            words.push_back(static_cast<std::uint16_t>(std::stoul(it->str(), nullptr, 16)));
    }
    return words;
}

// "1–6, 8, 13" -> {1, ..., 6, 8, 13}
std::vector<int> number_list(const std::string& s) {
    std::vector<int> out;
    std::stringstream in(s);
    std::string item;
    while (std::getline(in, item, ',')) {
        const std::size_t dash = item.find("–");
        if (dash == std::string::npos) {
            out.push_back(std::stoi(item));
        } else {
            const int a = std::stoi(item.substr(0, dash)),
                      b = std::stoi(item.substr(dash + std::string("–").size()));
            for (int v = a; v <= b; ++v) out.push_back(v);
        }
    }
    return out;
}

// The page's configuration size B + C·axes against config_registers(axes) for 1..kMaxAxes
// axes: one check, both series in the message.
void check_size_formula(const DocLine& l, long long b, long long c, const std::string& what) {
    std::ostringstream page, device;
    bool same = true;
    for (unsigned n = 1; n <= kMaxAxes; ++n) {
        page << (n > 1 ? ", " : "") << b + c * n;
        device << (n > 1 ? ", " : "") << mb::config_registers(n);
        same = same && b + c * n == mb::config_registers(n);
    }
    INFO(where(l) << "\n  " << what << ": the page's " << b << " + " << c << "·axes gives "
                  << page.str() << " for 1.." << kMaxAxes
                  << " axes; the device's config_registers(axes) gives " << device.str());
    CHECK(same);
}

// The page's offset B + C·axes + D·a against the device's for every axis a of 1..kMaxAxes
// axes: one check, the first difference in the message.
void check_offset_formula(const DocLine& l, long long b, long long c, long long d,
                          std::uint16_t (*device)(unsigned axes, unsigned axis),
                          const std::string& what) {
    std::ostringstream diff;
    for (unsigned n = 1; n <= kMaxAxes && diff.str().empty(); ++n) {
        for (unsigned a = 0; a < n && diff.str().empty(); ++a) {
            if (b + c * n + d * a != device(n, a))
                diff << "with " << n << " axes, axis " << a << ": the page's " << b << " + " << c
                     << "·axes + " << d << "a is " << b + c * n + d * a << ", the device's "
                     << device(n, a);
        }
    }
    INFO(where(l) << "\n  " << what << ": " << diff.str());
    CHECK(diff.str().empty());
}

const std::string kNum =
    "((?:−|-)?[0-9][0-9,]*[0-9]|(?:−|-)?[0-9])";  // a number as the page writes it

}  // namespace

TEST_CASE("docs/modbus.md: the protocol version as the device speaks it", "[doc][modbus]") {
    REQUIRE(!doc().lines.empty());
    const long long v = mb::kProtocolVersion;
    std::vector<std::string::const_iterator> checked;  // where the statements below stand
    if (auto f = find_one(prose("\\*\\*Protocol version (\\d+)\\*\\*"),
                          "the protocol version at the top")) {
        check_value(f->line, std::stoll(f->m[1]), v, "the protocol version");
        checked.push_back(f->m[1].first);
    }
    if (auto f =
            find_one("^\\| " + std::to_string(st::kVersion) + " \\| protocol version: (\\d+) \\|",
                     "the protocol version in register " + std::to_string(st::kVersion))) {
        check_value(f->line, std::stoll(f->m[1]), v,
                    "the protocol version in register " + std::to_string(st::kVersion));
        checked.push_back(f->m[1].first);
    }
    if (auto f = find_one(prose("Check magic, version (\\d+)"),
                          "the version a host checks (\"Writing a host\")")) {
        check_value(f->line, std::stoll(f->m[1]), v, "the version a host checks");
        checked.push_back(f->m[1].first);
    }
    // Anywhere else: "version N" is the current version unless it says what N added.
    for (const Found& f : find_all("[Vv]ersion:?\\**\\s+(\\d+)(\\**\\s+added\\b)?")) {
        if (std::find(checked.begin(), checked.end(), f.m[1].first) != checked.end()) continue;
        const long long n = std::stoll(f.m[1]);
        if (f.m[2].matched) {
            INFO(where(f.line) << "\n  tells of version " << n << ", but the device speaks version "
                               << v);
            CHECK((n >= 1 && n <= v));
        } else {
            check_value(f.line, n, v, "the protocol version");
        }
    }
}

TEST_CASE("docs/modbus.md: the status block as the device fills it", "[doc][modbus]") {
    const long long last = st::kCount - 1;
    if (auto f = find_one("^## Status block — input registers \\(FC4\\) (\\d+)–(\\d+), "
                          "mirrored read-only in holding registers (\\d+)–(\\d+)",
                          "the status block's range in its heading")) {
        check_value(f->line, std::stoll(f->m[1]), 0,
                    "the first input register of the status block");
        check_value(f->line, std::stoll(f->m[2]), last,
                    "the last input register of the status block");
        check_value(f->line, std::stoll(f->m[3]), 0, "the first register of the status mirror");
        check_value(f->line, std::stoll(f->m[4]), last, "the last register of the status mirror");
    }
    if (auto f = find_one(prose("`status::kCount` = (\\d+) registers"), "status::kCount"))
        check_value(f->line, std::stoll(f->m[1]), st::kCount, "status::kCount");
    if (auto f = find_one(prose("the status block is (\\d+) registers"),
                          "the status block's size at the top"))
        check_value(f->line, std::stoll(f->m[1]), st::kCount, "the status block's size");
    if (auto f = find_one(prose("Read the status block \\(FC4 (\\d+)–(\\d+)\\)"),
                          "the read in \"Writing a host\"")) {
        check_value(f->line, std::stoll(f->m[1]), 0, "the first register of the status block");
        check_value(f->line, std::stoll(f->m[2]), last, "the last register of the status block");
    }
    if (auto f = find_one(prose("polls registers (\\d+)–(\\d+)\\s*\\(`status::kStreamingCount`"),
                          "status::kStreamingCount")) {
        check_value(f->line, std::stoll(f->m[1]), 0, "the first register a streaming host polls");
        check_value(f->line, std::stoll(f->m[2]), st::kStreamingCount - 1,
                    "the last register a streaming host polls");
    }
    if (auto f = find_one(prose("Reads the status block \\(registers (\\d+)–(\\d+)\\)"),
                          "what `pathstream stream` reads")) {
        check_value(f->line, std::stoll(f->m[1]), 0, "the first register pathstream stream reads");
        check_value(f->line, std::stoll(f->m[2]), st::kStreamingCount - 1,
                    "the last register pathstream stream reads");
    }

    // The table: one row per register or register range, together exactly 0 .. kCount - 1.
    const auto [from, to] = section("^## Status block");
    struct Row {
        DocLine line;
        long long first, last;
    };
    std::vector<Row> rows;
    for (const Found& f : find_all("^\\| (\\d+)(?:–(\\d+))? \\|", from, to)) {
        const long long a = std::stoll(f.m[1]);
        rows.push_back({f.line, a, f.m[2].matched ? std::stoll(f.m[2]) : a});
    }
    REQUIRE(!rows.empty());
    long long next = 0;
    for (const Row& r : rows) {
        INFO(where(r.line)
             << "\n  the status table's rows must follow each other from register 0 on; this one "
                "should start at "
             << next);
        CHECK(r.first == next);
        next = r.last + 1;
    }
    {
        INFO(where(rows.back().line) << "\n  the status table ends at register " << rows.back().last
                                     << "; the device fills registers 0 to " << last);
        CHECK(rows.back().last == last);
    }
    // Every register the device fills (fill_status) starts a row of its width.
    struct Field {
        const char* name;
        std::uint16_t first;
        unsigned width;
    };
    const Field fields[] = {
        {"kMagic", st::kMagic, 1},
        {"kVersion", st::kVersion, 1},
        {"kState", st::kState, 1},
        {"kFaultCode", st::kFaultCode, 1},
        {"kFreeSlots", st::kFreeSlots, 1},
        {"kCapacity", st::kCapacity, 1},
        {"kLastAcceptedSequence (u32)", st::kLastAcceptedSequence, 2},
        {"kTicksExecuted (u32)", st::kTicksExecuted, 2},
        {"kPositions (i32 per axis)", st::kPositions, 2 * kMaxAxes},
        {"kAxes", st::kAxes, 1},
        {"kUnderruns", st::kUnderruns, 1},
        {"kLastCompletedSequence (u32)", st::kLastCompletedSequence, 2},
        {"kLastRefusal", st::kLastRefusal, 1},
        {"kRefusals", st::kRefusals, 1},
        {"kDuplicates", st::kDuplicates, 1},
        {"kOutputs", st::kOutputs, 1},
        {"kQueuedSpans", st::kQueuedSpans, 1},
        {"kFlags", st::kFlags, 1},
        {"kFinishedJob (u32)", st::kFinishedJob, 2},
        {"kFinishedJobTicks (u32)", st::kFinishedJobTicks, 2},
        {"kEpoch (u32)", st::kEpoch, 2},
        {"kHoming (one per axis)", st::kHoming, kMaxAxes},
    };
    for (const Field& f : fields) {
        const long long a = f.first, b = f.first + f.width - 1;
        bool found = false;
        for (const Row& r : rows) found = found || (r.first == a && r.last == b);
        INFO("docs/modbus.md: the status table has no row for registers "
             << a << (b != a ? "–" + std::to_string(b) : "") << " (status::" << f.name << ")");
        CHECK(found);
    }
    // The flags row names every flag bit.
    for (const Row& r : rows) {
        if (r.first != st::kFlags) continue;
        for (const std::uint16_t flag :
             {mb::flags::kConfigured, mb::flags::kHeldByUnderrun, mb::flags::kOwnMove,
              mb::flags::kHoming, mb::flags::kPaused}) {
            const std::string bit = "bit " + std::to_string(std::countr_zero(flag));
            INFO(where(r.line) << "\n  the flags row does not describe " << bit
                               << ", which the device sets");
            CHECK(r.line.text.find(bit) != std::string::npos);
        }
    }
}

TEST_CASE("docs/modbus.md: the configuration block as the device reads it", "[doc][modbus]") {
    // "(`config_registers(axes)` = B + C·axes registers", and every "B + C·axes registers".
    auto size_formulas = find_all(prose("(\\d+) \\+ (\\d+)·axes registers"));
    if (!find_one(prose("`config_registers\\(axes\\)` = (\\d+) \\+ (\\d+)·axes registers"),
                  "config_registers(axes)"))
        size_formulas.clear();
    for (const Found& f : size_formulas)
        check_size_formula(f.line, std::stoll(f.m[1]), std::stoll(f.m[2]),
                           "the configuration's size");
    // "… 30 with 2 axes, 90 with 8)" in the same row.
    for (const Found& f : find_all("`config_registers\\(axes\\)` = .*")) {
        const std::string rest = f.m[0];
        const std::regex re("(\\d+) with (\\d+)");
        for (auto it = std::sregex_iterator(rest.begin(), rest.end(), re);
             it != std::sregex_iterator(); ++it) {
            const unsigned axes = static_cast<unsigned>(std::stoul((*it)[2]));
            check_value(
                f.line, std::stoll((*it)[1]),
                axes >= 1 && axes <= kMaxAxes ? mb::config_registers(axes) : -1,
                "the configuration's register count with " + std::to_string(axes) + " axes");
        }
    }
    // The holding register row: "| 110 … 110 + B + C·axes − 1 |".
    if (auto f = find_one("^\\| (\\d+) … (\\d+) \\+ (\\d+) \\+ (\\d+)·axes − 1 \\|",
                          "the configuration's registers")) {
        check_value(f->line, std::stoll(f->m[1]), mb::kConfig,
                    "the configuration's first register");
        check_value(f->line, std::stoll(f->m[2]), mb::kConfig,
                    "the configuration's first register");
        check_size_formula(f->line, std::stoll(f->m[3]), std::stoll(f->m[4]),
                           "the configuration's registers");
    }
    if (auto f = find_one(prose("ending at (\\d+) with (\\d+) axes"),
                          "where 8 axes' configuration ends")) {
        const unsigned axes = static_cast<unsigned>(std::stoul(f->m[2]));
        check_value(
            f->line, std::stoll(f->m[1]),
            axes >= 1 && axes <= kMaxAxes ? mb::kConfig + mb::config_registers(axes) - 1 : -1,
            "the configuration's last register with " + std::to_string(axes) + " axes");
    }
    // The layout table's offsets against the map's own functions.
    if (auto f = find_one("^\\| \\+(\\d+) \\| (\\d+) \\| pen-down delay",
                          "the pen-down delay's register")) {
        check_value(f->line, std::stoll(f->m[1]), mb::kConfigPenDownTicks,
                    "the pen-down delay's offset");
        check_value(f->line, std::stoll(f->m[2]), mb::kConfig + mb::kConfigPenDownTicks,
                    "the pen-down delay's register");
    }
    if (auto f = find_one("^\\| \\+(\\d+)–(\\d+) \\| (\\d+)–(\\d+) \\| reserved",
                          "the reserved registers")) {
        check_value(f->line, std::stoll(f->m[1]), mb::kConfigPenDownTicks + 1,
                    "the first reserved offset");
        check_value(f->line, std::stoll(f->m[2]), mb::kConfigAxisBase - 1,
                    "the last reserved offset");
        check_value(f->line, std::stoll(f->m[3]), mb::kConfig + mb::kConfigPenDownTicks + 1,
                    "the first reserved register");
        check_value(f->line, std::stoll(f->m[4]), mb::kConfig + mb::kConfigAxisBase - 1,
                    "the last reserved register");
    }
    struct Offset {
        const char* field;
        std::uint16_t (*device)(unsigned axes, unsigned axis);
    };
    const Offset offsets[] = {
        {"travel min", [](unsigned n, unsigned a) { return mb::config_travel_register(n, a); }},
        {"travel max",  // the register after the min's pair
         [](unsigned n, unsigned a) {
             return static_cast<std::uint16_t>(mb::config_travel_register(n, a) + 2);
         }},
        {"max jerk", [](unsigned n, unsigned a) { return mb::config_jerk_register(n, a); }},
    };
    for (const Offset& o : offsets) {
        if (auto f = find_one("^\\| \\+(\\d+) \\+ (\\d+)·axes \\+ (\\d+)a, \\+1 \\| \\| axis a " +
                                  std::string(o.field),
                              std::string("axis a ") + o.field + "'s offset")) {
            check_offset_formula(f->line, std::stoll(f->m[1]), std::stoll(f->m[2]),
                                 std::stoll(f->m[3]), o.device, std::string("axis a's ") + o.field);
        }
    }
}

TEST_CASE("docs/modbus.md: the worked example runs on the device as the page says",
          "[doc][modbus]") {
    // The start point: "a freshly started device resting at (100000, −32)".
    auto at = find_one(prose("resting at \\(" + kNum + ", " + kNum + "\\)"),
                       "where the example's device rests");
    REQUIRE(at);
    const Lsb start[kExampleAxes] = {static_cast<Lsb>(number(at->m[1])),
                                     static_cast<Lsb>(number(at->m[2]))};
    ExampleDevice d(start);
    ExampleMap map(d);

    // The configuration: "is one FC16 of N registers at 110:" and its words in the code block
    // after.
    std::optional<Found> config, batch;
    for (const Found& f : find_all(prose("one FC16 of (\\d+) registers at (\\d+):"))) {
        if (std::stoll(f.m[2]) == mb::kConfig) config = f;
        if (std::stoll(f.m[2]) == mb::kSpanWindow) batch = f;
    }
    if (!config)
        FAIL_CHECK("docs/modbus.md: no \"one FC16 of N registers at "
                   << mb::kConfig << ":\" (the configuration example)");
    if (!batch)
        FAIL_CHECK("docs/modbus.md: no \"one FC16 of N registers at " << mb::kSpanWindow
                                                                      << ":\" (the batch example)");
    REQUIRE((config && batch));

    const std::vector<std::uint16_t> c = code_block_words(*config);
    const long long c_count = std::stoll(config->m[1]);
    {
        INFO(where(config->line) << "\n  says " << c_count
                                 << " registers; the code block after it (``` … ```) has "
                                 << c.size());
        CHECK(static_cast<long long>(c.size()) == c_count);
    }
    REQUIRE(c.size() > 2);
    {
        INFO(where(config->line) << "\n  the example configures " << c[2]
                                 << " axes; the test runs it on " << kExampleAxes);
        REQUIRE(c[2] == kExampleAxes);
    }
    check_value(config->line, c_count, mb::config_registers(c[2]),
                "the configuration's register count with " + std::to_string(c[2]) + " axes");
    {
        const Ex e = map.write_holding_registers(mb::kConfig, static_cast<std::uint16_t>(c.size()),
                                                 c.data());
        std::uint16_t refusal = 0;
        REQUIRE(map.read_input_registers(st::kLastRefusal, 1, &refusal) == Ex::kNone);
        INFO(where(config->line) << "\n  the device refuses the example configuration: exception "
                                 << static_cast<int>(e) << ", status " << refusal << " ("
                                 << status_name(static_cast<Status>(refusal)) << ")");
        REQUIRE(e == Ex::kNone);
    }
    // What the sentence says the words are: "(1,000 Hz, 2 axes, …, 2,000 LSB/s and 250,000 LSB/s²
    // per axis".
    if (auto f = find_one(
            prose("configuration for that example \\(" + kNum + " Hz, (\\d+) axes,[^)]*? " + kNum +
                  " LSB/s and " + kNum + " LSB/s² per axis"),
            "the example configuration's tick rate, axes and limits")) {
        check_value(f->line, number(f->m[1]), d.limits().tick_hz,
                    "the example's tick rate (as its words configure it)");
        check_value(f->line, std::stoll(f->m[2]), kExampleAxes, "the example's axis count");
        for (unsigned a = 0; a < kExampleAxes; ++a) {
            check_value(f->line, number(f->m[3]), d.limits().axis[a].max_velocity,
                        "axis " + std::to_string(a) +
                            "'s max velocity (as the example's words configure it)");
            check_value(f->line, number(f->m[4]), d.limits().axis[a].max_acceleration,
                        "axis " + std::to_string(a) +
                            "'s max acceleration (as the example's words configure it)");
        }
    }

    // The batch: header, CRC, and the device accepts it.
    const std::vector<std::uint16_t> b = code_block_words(*batch);
    const long long b_count = std::stoll(batch->m[1]);
    {
        INFO(where(batch->line) << "\n  says " << b_count
                                << " registers; the code block after it (``` … ```) has "
                                << b.size());
        CHECK(static_cast<long long>(b.size()) == b_count);
    }
    REQUIRE(b.size() > mb::kSpanHeaderRegisters);
    const std::size_t bytes = b[3];
    std::vector<std::uint8_t> payload;
    for (std::size_t i = mb::kSpanHeaderRegisters; i < b.size(); ++i) {
        payload.push_back(static_cast<std::uint8_t>(b[i] >> 8));
        payload.push_back(static_cast<std::uint8_t>(b[i] & 0xFFu));
    }
    check_value(batch->line, static_cast<long long>(b.size() - mb::kSpanHeaderRegisters),
                static_cast<long long>((bytes + 1) / 2),
                "the payload registers for " + std::to_string(bytes) + " bytes");
    REQUIRE(payload.size() >= bytes);
    const std::uint16_t crc = device::crc16_modbus(payload.data(), bytes);
    check_value(batch->line, b[4], crc, "the CRC register (CRC-16/MODBUS of the payload)");
    if (auto f = find_one(prose("(\\d+) bytes, CRC 0x([0-9A-Fa-f]{4})"),
                          "the example batch's length and CRC")) {
        check_value(f->line, std::stoll(f->m[1]), bytes,
                    "the example batch's bytes (register 203 of its words)");
        check_value(f->line, std::stoll(f->m[2], nullptr, 16), crc, "the example batch's CRC");
    }
    {
        const Ex e = map.write_holding_registers(mb::kSpanWindow,
                                                 static_cast<std::uint16_t>(b.size()), b.data());
        std::uint16_t refusal = 0;
        REQUIRE(map.read_input_registers(st::kLastRefusal, 1, &refusal) == Ex::kNone);
        INFO(where(batch->line) << "\n  the device refuses the example batch: exception "
                                << static_cast<int>(e) << ", status " << refusal << " ("
                                << status_name(static_cast<Status>(refusal)) << ")");
        REQUIRE(e == Ex::kNone);
    }

    // "FC6 register 100 = 1 starts the job", then "the 17th tick makes the device idle at
    // (100016, −40) with registers 36–37 = 1 (the job id), 38–39 = 16 and 28–29 = 2".
    auto go = find_one(prose("FC6 register (\\d+) = (\\d+) starts the job"), "the example's start");
    REQUIRE(go);
    check_value(go->line, std::stoll(go->m[1]), mb::kCommand, "the command register");
    const std::uint16_t command = static_cast<std::uint16_t>(std::stoul(go->m[2]));
    REQUIRE(map.write_holding_registers(static_cast<std::uint16_t>(std::stoul(go->m[1])), 1,
                                        &command) == Ex::kNone);
    auto end = find_one(
        prose("the (\\d+)(?:st|nd|rd|th) tick makes the device idle at \\(" + kNum + ", " + kNum +
              "\\) with registers (\\d+)–(\\d+) = (\\d+) \\(the job id\\), (\\d+)–(\\d+) = (\\d+) "
              "and (\\d+)–(\\d+) = (\\d+)"),
        "how the example ends");
    REQUIRE(end);
    const long long ticks = std::stoll(end->m[1]);
    REQUIRE((ticks >= 1 && ticks < 100000));
    Lsb out[kExampleAxes];
    for (long long k = 1; k < ticks; ++k) d.tick(out);
    {
        INFO(where(end->line) << "\n  the device is idle after " << ticks - 1 << " ticks already");
        CHECK(d.state() != device::DeviceState::kIdle);
    }
    d.tick(out);
    {
        INFO(where(end->line) << "\n  the device is not idle after " << ticks << " ticks (state "
                              << static_cast<int>(d.state()) << ")");
        CHECK(d.state() == device::DeviceState::kIdle);
    }
    for (unsigned a = 0; a < kExampleAxes; ++a)
        check_value(end->line, number(end->m[2 + a]), d.position(a),
                    "axis " + std::to_string(a) + "'s end point");
    std::uint16_t s[st::kCount];
    REQUIRE(map.read_input_registers(0, st::kCount, s) == Ex::kNone);
    const std::uint16_t named[3] = {st::kFinishedJob, st::kFinishedJobTicks,
                                    st::kLastCompletedSequence};
    const char* names[3] = {"the finished job's registers", "the finished job ticks' registers",
                            "the last completed sequence's registers"};
    for (int i = 0; i < 3; ++i) {
        const long long first = std::stoll(end->m[4 + 3 * i]),
                        second = std::stoll(end->m[5 + 3 * i]);
        const long long value = std::stoll(end->m[6 + 3 * i]);
        check_value(end->line, first, named[i], std::string("the first of ") + names[i]);
        check_value(end->line, second, named[i] + 1, std::string("the second of ") + names[i]);
        if (first >= 0 && first + 1 < st::kCount)
            check_value(end->line, value, (static_cast<long long>(s[first]) << 16) | s[first + 1],
                        "the value of registers " + std::to_string(first) + "–" +
                            std::to_string(first + 1));
    }
}

TEST_CASE("docs/modbus.md: every status answers the exception the page lists", "[doc][modbus]") {
    const auto [from, to] = section("^## Validation and exceptions");
    // "| 03 illegal data value | 1–6, 8–11, 13: …"
    std::map<int, std::pair<int, DocLine>> listed;  // status -> exception code, line
    auto rows = find_all("^\\| (\\d{2}) [^|\\n]*\\| ((?:\\d+|, |–)+):", from, to);
    REQUIRE(!rows.empty());
    for (const Found& f : rows) {
        const int row_exception = std::stoi(f.m[1]);
        for (int v : number_list(f.m[2])) {
            if (listed.count(v) != 0) {
                FAIL_CHECK(where(f.line)
                           << "\n  lists status " << v << " again (also under exception "
                           << code(listed[v].first) << ")");
            }
            listed[v] = {row_exception, f.line};
        }
    }
    const std::string no_status = status_name(static_cast<Status>(0xFF));
    // Status 0 stands for an address error: the status register after a write the map cannot place.
    ExampleDevice d({0, 0});
    ExampleMap map(d);
    const std::uint16_t one = 1;
    const Ex address_error =
        map.write_holding_registers(st::kState, 1, &one);  // a write to the status mirror
    std::uint16_t refusal = 0xFFFF;
    REQUIRE(map.read_input_registers(st::kLastRefusal, 1, &refusal) == Ex::kNone);
    for (int v = 0; v <= 0xFF; ++v) {
        const Status s = static_cast<Status>(v);
        const bool is_status = v == 0 || no_status != status_name(s);
        const auto it = listed.find(v);
        if (!is_status) {
            if (it != listed.end())
                FAIL_CHECK(where(it->second.second)
                           << "\n  lists status " << v << ", which the device does not have");
            continue;
        }
        const int expected = static_cast<int>(v == 0 ? address_error : exception_for(s));
        const std::string name = v == 0 ? "an address error" : status_name(s);
        if (v == 0) {
            INFO("a write to the status mirror answers exception "
                 << code(expected) << " and leaves status " << refusal << " in register "
                 << st::kLastRefusal);
            CHECK(refusal == 0);
        }
        if (it == listed.end()) {
            FAIL_CHECK("docs/modbus.md: the exceptions table does not list status "
                       << v << " (" << name << "); the device answers it with exception "
                       << code(expected));
            continue;
        }
        INFO(where(it->second.second)
             << "\n  lists status " << v << " (" << name << ") under exception "
             << code(it->second.first) << "; the device answers it with exception "
             << code(expected));
        CHECK(it->second.first == expected);
    }
}

TEST_CASE("docs/modbus.md: what a read of the span window answers", "[doc][modbus]") {
    ExampleDevice d({0, 0});
    ExampleMap map(d);
    std::uint16_t r = 0;
    const int read = static_cast<int>(map.read_holding_registers(mb::kSpanWindow, 1, &r));
    const int fc23 = static_cast<int>(
        map.write_read_holding_registers(mb::kCommand, 1, &r, mb::kSpanWindow, 1, &r));
    auto row =
        find_one("^\\| (\\d+) … \\| span window", "the span window's row in \"Holding registers\"");
    REQUIRE(row);
    check_value(row->line, std::stoll(row->m[1]), mb::kSpanWindow,
                "the span window's first register");
    const std::smatch ex = [&] {
        std::smatch m;
        static const std::regex re("read[^|]*exception (\\d{2})");
        std::regex_search(row->line.text, m, re);
        return m;
    }();
    if (ex.empty()) {
        FAIL_CHECK(where(row->line)
                   << "\n  does not say what a read of it answers (\"read … exception NN\"); "
                      "the device answers exception "
                   << code(read));
        return;
    }
    check_value(row->line, std::stoll(ex[1]), read,
                "the exception a read (FC3) of the span window answers");
    check_value(row->line, std::stoll(ex[1]), fc23,
                "the exception an FC23 reading the span window answers");
}
