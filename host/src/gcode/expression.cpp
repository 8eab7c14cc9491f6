// Expression evaluation with LinuxCNC's precedence: ** ; * / MOD ; + - ; EQ NE GT GE LT LE ;
// AND OR XOR, each level left to right; angles in degrees.
#include "expression.hpp"

#include <charconv>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <optional>

namespace pathstream::host::gcode {

std::string describe_char(char c) {
    const auto u = static_cast<unsigned char>(c);
    if (u >= 0x21 && u < 0x7f) return std::string("'") + c + "'";
    char buffer[8];
    std::snprintf(buffer, sizeof buffer, "\\x%02X", u);
    return std::string("byte ") + buffer;
}

namespace {

constexpr int kMaxNesting = 64;           // brackets, functions and ## within one value
constexpr double kEqualTolerance = 1e-6;  // LinuxCNC's TOLERANCE_EQUAL for EQ and NE

enum class Op {
    kPower,
    kTimes,
    kDivide,
    kMod,
    kPlus,
    kMinus,
    kEq,
    kNe,
    kGt,
    kGe,
    kLt,
    kLe,
    kAnd,
    kOr,
    kXor
};

// Binding strength: higher binds tighter (LinuxCNC's five levels).
int precedence(Op op) {
    switch (op) {
        case Op::kPower:
            return 4;
        case Op::kTimes:
        case Op::kDivide:
        case Op::kMod:
            return 3;
        case Op::kPlus:
        case Op::kMinus:
            return 2;
        case Op::kEq:
        case Op::kNe:
        case Op::kGt:
        case Op::kGe:
        case Op::kLt:
        case Op::kLe:
            return 1;
        default:
            return 0;
    }
}

// RS274NGC angles are in degrees.
double radians(double degrees) {
    return degrees * std::numbers::pi / 180.0;
}
// RS274NGC angles are in degrees.
double degrees(double radians_value) {
    return radians_value * 180.0 / std::numbers::pi;
}

// Six significant digits: enough to recognise a value in a message.
std::string number_text(double v) {
    char buffer[32];
    std::snprintf(buffer, sizeof buffer, "%.6g", v);
    return buffer;
}

class ValueReader {
public:
    ValueReader(LineCursor& cursor, const Parameters& parameters, char letter, std::size_t word_at)
        : c_(cursor), parameters_(parameters), letter_(letter), word_at_(word_at) {}

    // One value: number, [expression], #parameter, function, or a signed one of these.
    double value() {
        const Depth depth(*this);
        c_.skip_blanks();
        const std::size_t at = c_.i;
        const char ch = c_.peek();
        double v = 0;
        if (ch == '[') {
            v = bracketed();
        } else if (ch == '#') {
            const ParameterRef ref = parameter_ref();
            const std::optional<double> found = parameters_.get(ref);
            if (!found) c_.fail(at, "parameter " + parameter_text(ref) + " is not defined");
            v = *found;
        } else if (ch == '-' || ch == '+') {
            const std::size_t sign = c_.i++;
            const char next = c_.peek();
            if (next != '[' && next != '#' && !is_letter(next)) {
                c_.i = sign;
                v = number();
            } else {
                v = value();
                if (ch == '-') v = -v;
            }
        } else if (is_letter(ch)) {
            if (plain() && !is_function_name()) c_.fail(word_at_, missing());
            v = function();
        } else if (is_digit(ch) || ch == '.') {
            v = number();
        } else {
            c_.fail(at, c_.done() ? missing()
                                  : "unexpected character " + describe_char(ch) + " " + where());
        }
        return finite(v, at);
    }

    // The parameter named after a '#': a number, a <name>, or a value giving the number.
    ParameterRef parameter_ref() {
        const Depth depth(*this);
        const std::size_t at = c_.i++;  // the '#'
        c_.skip_blanks();
        ParameterRef ref;
        if (c_.peek() == '<') {
            const std::size_t close = c_.text.find('>', c_.i);
            if (close == std::string_view::npos) c_.fail(c_.i, "unclosed parameter name '<'");
            for (std::size_t k = c_.i + 1; k < close; ++k) {
                const char ch = c_.text[k];
                if (!is_blank(ch))
                    ref.name += ch >= 'A' && ch <= 'Z' ? static_cast<char>(ch - 'A' + 'a') : ch;
            }
            if (ref.name.empty()) c_.fail(c_.i, "empty parameter name '<>'");
            c_.i = close + 1;
            return ref;
        }
        // "#[1+2]", "##1", and as LinuxCNC a function: "#ATAN[1]/[1]" is #45.
        const double n =
            c_.peek() == '#' || c_.peek() == '[' || is_letter(c_.peek()) ? value() : number();
        const double whole = std::round(n);
        if (std::fabs(n - whole) > 1e-6 || whole < 1 ||
            whole > static_cast<double>(Parameters::kMaxParameter)) {
            c_.fail(at, "parameter number " + number_text(n) + " is not a whole number from 1 to " +
                            std::to_string(Parameters::kMaxParameter));
        }
        ref.number = static_cast<long>(whole);
        return ref;
    }

private:
    struct Depth {
        explicit Depth(ValueReader& r) : reader(r) {
            if (++reader.depth_ > kMaxNesting) {
                reader.c_.fail(reader.c_.i, "expression nested more than " +
                                                std::to_string(kMaxNesting) + " deep");
            }
        }
        ~Depth() { --reader.depth_; }
        ValueReader& reader;
    };

    // A word's own value, outside brackets: number errors go to the word's letter.
    bool plain() const { return letter_ != 0 && brackets_ == 0 && word_at_ != kNoWord; }
    std::size_t number_error_at(std::size_t begin) const { return plain() ? word_at_ : begin; }

    bool is_function_name() const {
        std::string name;
        for (std::size_t k = c_.i; k < c_.text.size() && is_letter(c_.text[k]); ++k)
            name += upper(c_.text[k]);
        for (const char* f : {"ABS", "ACOS", "ASIN", "ATAN", "COS", "EXISTS", "EXP", "FIX", "FUP",
                              "LN", "ROUND", "SIN", "SQRT", "TAN"}) {
            if (name == f) return true;
        }
        return false;
    }

    // Which word or O-word the value belongs to, for messages.
    std::string where() const {
        return letter_ ? std::string("in the value of ") + letter_
                       : std::string("in the expression");
    }
    // The message for a value that is not there.
    std::string missing() const {
        return letter_ ? std::string("missing number after ") + letter_
                       : std::string("missing value");
    }

    // Infinite or NaN values would poison every later computation: stop at their source.
    double finite(double v, std::size_t at) const {
        if (!std::isfinite(v)) c_.fail(at, "value is not finite (" + number_text(v) + ")");
        return v;
    }

    // [+-] digits [. digits] or [+-] . digits: no exponent, as LinuxCNC.
    double number() {
        const std::size_t begin = c_.i;
        if (c_.peek() == '+' || c_.peek() == '-') ++c_.i;
        // A word's plain number takes in stray signs ("X1-2"), to be reported as malformed;
        // inside brackets a sign is the next operator.
        const bool greedy = letter_ != 0 && brackets_ == 0;
        while (!c_.done() && (is_digit(c_.peek()) || c_.peek() == '.' ||
                              (greedy && (c_.peek() == '+' || c_.peek() == '-')))) {
            ++c_.i;
        }
        const std::string_view token = c_.text.substr(begin, c_.i - begin);
        if (token.empty()) c_.fail(number_error_at(begin), missing());
        auto malformed = [&] {
            c_.fail(number_error_at(begin),
                    "malformed number \"" + std::string(token) + "\"" +
                        (letter_ ? std::string(" after ") + letter_ : std::string()));
        };
        std::size_t k = 0;
        bool negative = false;
        if (token[k] == '+' || token[k] == '-') negative = token[k++] == '-';
        std::size_t digits = 0, points = 0;
        bool nonzero_integer_digit = false;
        for (std::size_t j = k; j < token.size(); ++j) {
            if (is_digit(token[j])) {
                ++digits;
                if (points == 0 && token[j] != '0') nonzero_integer_digit = true;
            } else if (token[j] == '.') {
                ++points;
            } else {
                malformed();  // a sign inside the number
            }
        }
        if (digits == 0 || points > 1) malformed();
        const std::string_view body = token.substr(k);
        double v = 0;
        const auto result = std::from_chars(body.data(), body.data() + body.size(), v);
        if (result.ec == std::errc::result_out_of_range) {
            if (nonzero_integer_digit) {
                c_.fail(number_error_at(begin),
                        (letter_ ? std::string("number after ") + letter_ : std::string("number")) +
                            " is out of range (not finite as a double)");
            }
            v = 0;  // underflow: closer to zero than any double
        } else if (result.ec != std::errc() || result.ptr != body.data() + body.size()) {
            malformed();
        }
        return negative ? -v : v;
    }

    // "[expression]"; the cursor is on the '['.
    double bracketed() {
        const std::size_t open = c_.i++;
        ++brackets_;
        const double v = expression(0);
        --brackets_;
        c_.skip_blanks();
        if (c_.peek() != ']') {
            c_.fail(c_.done() ? open : c_.i,
                    c_.done() ? "unclosed '['"
                              : "expected an operator or ']', found " + describe_char(c_.peek()));
        }
        ++c_.i;
        return v;
    }

    // Precedence climbing: operators of one level group left to right, as LinuxCNC.
    double expression(int min_precedence) {
        double left = value();
        while (true) {
            c_.skip_blanks();
            const std::size_t at = c_.i;
            const std::optional<Op> op = peek_operator();
            if (!op || precedence(*op) < min_precedence) {
                c_.i = at;
                return left;
            }
            const double right = expression(precedence(*op) + 1);
            left = finite(apply(*op, left, right, at), at);
        }
    }

    // Consumes and returns the operator at the cursor, if there is one.
    std::optional<Op> peek_operator() {
        const std::string_view rest = c_.text.substr(c_.i);
        auto symbol = [&](std::string_view s, Op op) -> std::optional<Op> {
            if (rest.substr(0, s.size()) != s) return std::nullopt;
            c_.i += s.size();
            return op;
        };
        if (auto op = symbol("**", Op::kPower)) return op;
        if (auto op = symbol("*", Op::kTimes)) return op;
        if (auto op = symbol("/", Op::kDivide)) return op;
        if (auto op = symbol("+", Op::kPlus)) return op;
        if (auto op = symbol("-", Op::kMinus)) return op;
        std::string word;
        for (std::size_t k = 0; k < rest.size() && k < 3 && is_letter(rest[k]); ++k)
            word += upper(rest[k]);
        static const struct {
            const char* name;
            Op op;
        } kWords[] = {{"MOD", Op::kMod}, {"AND", Op::kAnd}, {"XOR", Op::kXor}, {"EQ", Op::kEq},
                      {"NE", Op::kNe},   {"GT", Op::kGt},   {"GE", Op::kGe},   {"LT", Op::kLt},
                      {"LE", Op::kLe},   {"OR", Op::kOr}};
        for (const auto& w : kWords) {
            const std::string_view name(w.name);
            if (std::string_view(word).substr(0, name.size()) == name) {
                c_.i += name.size();
                return w.op;
            }
        }
        return std::nullopt;
    }

    // LinuxCNC's execute_binary, with its errors.
    double apply(Op op, double a, double b, std::size_t at) const {
        switch (op) {
            case Op::kPower:
                if (a < 0 && b != std::floor(b)) {
                    c_.fail(at, "negative number " + number_text(a) +
                                    " raised to the non-integer power " + number_text(b));
                }
                if (a == 0 && b < 0) c_.fail(at, "zero raised to a negative power");
                return std::pow(a, b);
            case Op::kTimes:
                return a * b;
            case Op::kDivide:
                if (b == 0) c_.fail(at, "division by zero");
                return a / b;
            case Op::kMod: {
                if (b == 0) c_.fail(at, "MOD by zero");
                double r = std::fmod(a, b);
                if (r < 0) r += std::fabs(b);  // as LinuxCNC: the result is never negative
                return r;
            }
            case Op::kPlus:
                return a + b;
            case Op::kMinus:
                return a - b;
            case Op::kEq:
                return std::fabs(a - b) < kEqualTolerance ? 1 : 0;
            case Op::kNe:
                return std::fabs(a - b) >= kEqualTolerance ? 1 : 0;
            case Op::kGt:
                return a > b ? 1 : 0;
            case Op::kGe:
                return a >= b ? 1 : 0;
            case Op::kLt:
                return a < b ? 1 : 0;
            case Op::kLe:
                return a <= b ? 1 : 0;
            case Op::kAnd:
                return a != 0 && b != 0 ? 1 : 0;
            case Op::kOr:
                return a != 0 || b != 0 ? 1 : 0;
            case Op::kXor:
                return (a != 0) != (b != 0) ? 1 : 0;
        }
        return 0;
    }

    // NAME[value], ATAN[y]/[x], EXISTS[#<name>]; LinuxCNC's execute_unary, with its errors.
    double function() {
        const std::size_t at = c_.i;
        std::string name;
        while (is_letter(c_.peek())) name += upper(c_.text[c_.i++]);
        c_.skip_blanks();
        if (c_.peek() != '[') {
            c_.fail(at, "unknown function or missing '[' after \"" + name + "\" " + where() +
                            " (functions: ABS ACOS ASIN ATAN COS EXISTS EXP FIX FUP LN ROUND SIN "
                            "SQRT TAN)");
        }
        if (name == "EXISTS") return exists();
        const double x = bracketed();
        auto domain = [&](bool ok, const char* what) {
            if (!ok) c_.fail(at, name + " of " + number_text(x) + ": " + what);
        };
        if (name == "ATAN") {
            c_.skip_blanks();
            if (c_.peek() != '/') c_.fail(c_.i, "ATAN needs two arguments: ATAN[y]/[x]");
            ++c_.i;
            c_.skip_blanks();
            if (c_.peek() != '[') c_.fail(c_.i, "ATAN needs two arguments: ATAN[y]/[x]");
            const double y = bracketed();
            return degrees(std::atan2(x, y));
        }
        if (name == "ABS") return std::fabs(x);
        if (name == "ACOS") {
            domain(x >= -1 && x <= 1, "not in -1..1");
            return degrees(std::acos(x));
        }
        if (name == "ASIN") {
            domain(x >= -1 && x <= 1, "not in -1..1");
            return degrees(std::asin(x));
        }
        if (name == "COS") return std::cos(radians(x));
        if (name == "EXP") return std::exp(x);
        if (name == "FIX") return std::floor(x);
        if (name == "FUP") return std::ceil(x);
        if (name == "ROUND") return std::round(x);
        if (name == "LN") {
            domain(x > 0, "not positive");
            return std::log(x);
        }
        if (name == "SIN") return std::sin(radians(x));
        if (name == "SQRT") {
            domain(x >= 0, "negative");
            return std::sqrt(x);
        }
        if (name == "TAN") return std::tan(radians(x));
        c_.fail(
            at,
            "unknown function " + name +
                " (functions: ABS ACOS ASIN ATAN COS EXISTS EXP FIX FUP LN ROUND SIN SQRT TAN)");
    }

    // EXISTS[#<name>]: 1 when the named parameter is defined; never reads it.
    double exists() {
        const std::size_t open = c_.i++;
        c_.skip_blanks();
        if (c_.peek() != '#') c_.fail(c_.i, "EXISTS takes a parameter: EXISTS[#<name>]");
        const ParameterRef ref = parameter_ref();
        c_.skip_blanks();
        if (c_.peek() != ']') c_.fail(c_.done() ? open : c_.i, "expected ']' after EXISTS[#<name>");
        ++c_.i;
        // A numbered parameter always exists (it is 0 until set), as LinuxCNC answers.
        return ref.name.empty() || parameters_.exists(ref.name) ? 1 : 0;
    }

    LineCursor& c_;
    const Parameters& parameters_;
    char letter_;
    int depth_ = 0;
    int brackets_ = 0;  ///< open '[' around the cursor
    std::size_t word_at_;
    static constexpr std::size_t kNoWord = static_cast<std::size_t>(-1);
};

}  // namespace

double read_value(LineCursor& cursor, const Parameters& parameters, char letter,
                  std::size_t word_at) {
    return ValueReader(cursor, parameters, letter, word_at).value();
}

ParameterRef read_parameter_ref(LineCursor& cursor, const Parameters& parameters) {
    return ValueReader(cursor, parameters, 0, static_cast<std::size_t>(-1)).parameter_ref();
}

}  // namespace pathstream::host::gcode
