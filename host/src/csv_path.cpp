#include "pathstream/host/csv_path.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string_view>
#include <vector>

#include "pathstream/machine/input_error.hpp"

namespace pathstream::host {

namespace {

constexpr std::size_t kMaxAxes = 8;
constexpr double kMaxCoordinateMm = 1e6;  // as the JSON reader: catches unit mix-ups

bool is_blank(char c) {
    return c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v';
}

std::string_view trim(std::string_view s) {
    while (!s.empty() && is_blank(s.front())) s.remove_prefix(1);
    while (!s.empty() && is_blank(s.back())) s.remove_suffix(1);
    return s;
}

struct Field {
    std::string_view text;  // without surrounding blanks
    std::size_t column;     // 1-based column of its first character (of the comma if empty)
};

std::vector<Field> split(std::string_view line) {
    std::vector<Field> fields;
    std::size_t begin = 0;
    while (true) {
        const std::size_t comma = line.find(',', begin);
        const std::string_view raw =
            line.substr(begin, comma == std::string_view::npos ? line.npos : comma - begin);
        std::size_t lead = 0;
        while (lead < raw.size() && is_blank(raw[lead])) ++lead;
        fields.push_back({trim(raw), begin + lead + 1});
        if (comma == std::string_view::npos) break;
        begin = comma + 1;
    }
    return fields;
}

enum class Parsed { kNumber, kNotANumber, kOverflow };

// from_chars reports overflow and underflow alike; an underflow is a number closer to zero
// than any double. Tells them apart by the decimal exponent of the first significant digit.
bool overflows(std::string_view s) {
    const std::size_t e = s.find_first_of("eE");
    long exponent = 0;
    if (e != std::string_view::npos) {
        const std::string digits(s.substr(e + 1));
        exponent =
            std::clamp(std::strtol(digits.c_str(), nullptr, 10), -1'000'000'000L, 1'000'000'000L);
    }
    long integer_digits = 0, index = 0, first_significant = -1;
    bool after_point = false;
    for (const char c : s.substr(0, e)) {
        if (c == '.') {
            after_point = true;
        } else if (c >= '0' && c <= '9') {
            if (!after_point) ++integer_digits;
            if (c != '0' && first_significant < 0) first_significant = index;
            ++index;
        }
    }
    return first_significant >= 0 && integer_digits - 1 - first_significant + exponent > 0;
}

Parsed parse_number(std::string_view s, double& value) {
    std::string_view body = s;
    if (!body.empty() && body.front() == '+') {
        body.remove_prefix(1);
        if (!body.empty() && (body.front() == '+' || body.front() == '-'))
            return Parsed::kNotANumber;
    }
    const auto result = std::from_chars(body.data(), body.data() + body.size(), value);
    if (body.empty() || result.ptr != body.data() + body.size()) return Parsed::kNotANumber;
    if (result.ec == std::errc::result_out_of_range) {
        if (overflows(body)) return Parsed::kOverflow;
        value = 0;
        return Parsed::kNumber;
    }
    return result.ec == std::errc() ? Parsed::kNumber : Parsed::kNotANumber;
}

class Reader {
public:
    explicit Reader(const std::string& file) : file_(file) {}

    [[noreturn]] void fail(std::size_t line, std::size_t column, const std::string& message) const {
        throw InputError(file_, SourceLocation{line, column}, message);
    }

    double coordinate(const Field& f, std::size_t line) const {
        if (f.text.empty()) fail(line, f.column, "empty field (expected a number)");
        double value = 0;
        switch (parse_number(f.text, value)) {
            case Parsed::kNotANumber:
                fail(line, f.column, "\"" + std::string(f.text) + "\" is not a number");
            case Parsed::kOverflow:
                fail(line, f.column,
                     "number " + std::string(f.text) + " is out of range (not finite as a double)");
            case Parsed::kNumber:
                break;
        }
        if (!std::isfinite(value)) fail(line, f.column, "coordinate is not finite");
        if (std::fabs(value) > kMaxCoordinateMm) {
            std::ostringstream m;
            m << "coordinate " << value << " is out of range (|value| <= " << kMaxCoordinateMm
              << " mm)";
            fail(line, f.column, m.str());
        }
        return value;
    }

    static bool is_header(const std::vector<Field>& fields) {
        for (const Field& f : fields) {
            double ignored = 0;
            if (!f.text.empty() && parse_number(f.text, ignored) != Parsed::kNotANumber)
                return false;
        }
        return true;
    }

    void check_count(const Subpath& sp) const {
        if (const std::string problem = point_count_problem(sp); !problem.empty()) {
            throw InputError(file_, sp.location, problem);
        }
    }

    Path path(std::string_view text, PathBasis basis, bool closed) const {
        Subpath sp;
        sp.basis = basis;
        sp.closed = closed;
        std::size_t axes = 0;
        bool first_content = true;
        if (text.substr(0, 3) == "\xEF\xBB\xBF") text.remove_prefix(3);  // UTF-8 byte order mark
        // At most one point a line: reserved at once (with the first point, which sets the axes),
        // the list never grows by copying.
        const std::size_t lines =
            static_cast<std::size_t>(std::count(text.begin(), text.end(), '\n')) + 1;
        for (std::size_t line = 1; !text.empty(); ++line) {
            const std::size_t end = text.find('\n');
            const std::string_view current = text.substr(0, end);
            text.remove_prefix(end == std::string_view::npos ? text.size() : end + 1);
            const std::string_view content = trim(current);
            if (content.empty() || content.front() == '#') continue;
            const std::vector<Field> fields = split(current);
            const bool header = first_content && is_header(fields);
            first_content = false;
            if (fields.size() > kMaxAxes && axes == 0) {
                fail(line, fields[kMaxAxes].column,
                     (header ? "header has " : "point has ") + std::to_string(fields.size()) +
                         (header ? " columns" : " coordinates") + " (1 to 8 axes)");
            }
            if (header) {
                axes = fields.size();
                continue;
            }
            if (axes == 0) axes = fields.size();
            if (fields.size() != axes) {
                const Field& at = fields.size() > axes ? fields[axes] : fields.back();
                fail(line, at.column,
                     "point has " + std::to_string(fields.size()) + " coordinates, expected " +
                         std::to_string(axes));
            }
            double point[kMaxAxes];
            for (std::size_t a = 0; a < axes; ++a) point[a] = coordinate(fields[a], line);
            if (sp.points.empty()) {
                sp.location = SourceLocation{line, fields.front().column};
                sp.points.reserve(lines, axes);
            }
            sp.points.push_back(PointRef(point, axes));
        }
        check_count(sp);
        Path p;
        p.axes = axes;
        p.subpaths.push_back(std::move(sp));
        return p;
    }

private:
    const std::string& file_;
};

}  // namespace

Path parse_csv_path(const std::string& text, const std::string& file, PathBasis basis,
                    bool closed) {
    return Reader(file).path(text, basis, closed);
}

Path load_csv_path(const std::string& file, PathBasis basis, bool closed) {
    std::ifstream in(file, std::ios::binary);
    if (!in) throw InputError(file, {}, "cannot open file");
    std::ostringstream buffer;
    buffer << in.rdbuf();
    if (in.bad()) throw InputError(file, {}, "cannot read file");
    return parse_csv_path(buffer.str(), file, basis, closed);
}

}  // namespace pathstream::host
