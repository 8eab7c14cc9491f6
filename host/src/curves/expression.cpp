// Recursive descent over the grammar in docs/parametric-curves.md. Nodes are appended as their
// operands complete, which yields post-order for free.
#include "expression.hpp"

#include <array>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdio>

namespace pathstream::host::curves {

namespace {

struct Function {
    std::string_view name;
    Op op;
    int arguments;
};

constexpr std::array<Function, 20> kFunctions{{
    {"sin", Op::kSin, 1},     {"cos", Op::kCos, 1},
    {"tan", Op::kTan, 1},     {"asin", Op::kAsin, 1},
    {"acos", Op::kAcos, 1},   {"atan", Op::kAtan, 1},
    {"atan2", Op::kAtan2, 2}, {"sqrt", Op::kSqrt, 1},
    {"exp", Op::kExp, 1},     {"ln", Op::kLn, 1},
    {"log10", Op::kLog10, 1}, {"abs", Op::kAbs, 1},
    {"sinh", Op::kSinh, 1},   {"cosh", Op::kCosh, 1},
    {"tanh", Op::kTanh, 1},   {"min", Op::kMin, 2},
    {"max", Op::kMax, 2},     {"pow", Op::kPow, 2},
    {"hypot", Op::kHypot, 2}, {"fresnel_c", Op::kFresnelC, 1},
}};

const Function* find_function(std::string_view name) {
    for (const Function& f : kFunctions) {
        if (f.name == name) return &f;
    }
    if (name == "fresnel_s") {
        static constexpr Function kFresnelS{"fresnel_s", Op::kFresnelS, 1};
        return &kFresnelS;
    }
    return nullptr;
}

std::string function_list() {
    std::string list;
    for (const Function& f : kFunctions) list += std::string(f.name) + " ";
    return list + "fresnel_s";
}

// A character for a message: itself when printable, else its byte value.
std::string shown(char c) {
    if (std::isprint(static_cast<unsigned char>(c))) return std::string("\"") + c + "\"";
    char buffer[16];
    std::snprintf(buffer, sizeof buffer, "byte 0x%02x", static_cast<unsigned char>(c));
    return buffer;
}

bool identifier_start(char c) {
    return std::isalpha(static_cast<unsigned char>(c)) || c == '_';
}

bool identifier_char(char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || c == '_';
}

bool digit(char c) {
    return c >= '0' && c <= '9';
}

class Parser {
public:
    explicit Parser(std::string_view text) : text_(text) {}

    Expression run() {
        skip_space();
        if (at_end()) fail(1, "empty expression");
        expression();
        skip_space();
        if (!at_end()) {
            if (text_[pos_] == ')') fail(pos_ + 1, "unexpected \")\" (no \"(\" to close)");
            fail(pos_ + 1, "expected an operator before " + shown(text_[pos_]));
        }
        return Expression{std::move(nodes_), std::string(text_)};
    }

private:
    [[noreturn]] void fail(std::size_t column, const std::string& message) const {
        throw ExpressionError(column, message);
    }

    bool at_end() const { return pos_ >= text_.size(); }

    void skip_space() {
        while (!at_end() && std::isspace(static_cast<unsigned char>(text_[pos_]))) ++pos_;
    }

    // Skips spaces; true (and consumes it) when the next character is c.
    bool take(char c) {
        skip_space();
        if (at_end() || text_[pos_] != c) return false;
        ++pos_;
        return true;
    }

    std::uint32_t push(Node node, std::size_t column) {
        if (nodes_.size() >= kMaxExpressionNodes)
            fail(column, "more than " + std::to_string(kMaxExpressionNodes) +
                             " nodes (numbers, names and operations)");
        nodes_.push_back(node);
        return static_cast<std::uint32_t>(nodes_.size() - 1);
    }

    std::uint32_t binary(Op op, std::uint32_t a, std::uint32_t b, std::size_t column) {
        return push(Node{op, 0, a, b}, column);
    }

    std::uint32_t expression() {
        std::uint32_t left = term();
        for (;;) {
            const std::size_t column = pos_ + 1;
            if (take('+')) {
                left = binary(Op::kAdd, left, term(), column);
            } else if (take('-')) {
                left = binary(Op::kSub, left, term(), column);
            } else {
                return left;
            }
        }
    }

    std::uint32_t term() {
        std::uint32_t left = unary();
        for (;;) {
            skip_space();
            const std::size_t column = pos_ + 1;
            if (take('*')) {
                left = binary(Op::kMul, left, unary(), column);
            } else if (take('/')) {
                left = binary(Op::kDiv, left, unary(), column);
            } else {
                return left;
            }
        }
    }

    // Every nesting (parentheses, arguments, signs, exponents) passes through here, so the
    // depth counted here bounds the recursion.
    std::uint32_t unary() {
        skip_space();
        const std::size_t column = pos_ + 1;
        if (++depth_ > kMaxExpressionDepth)
            fail(column, "nested deeper than " + std::to_string(kMaxExpressionDepth) +
                             " levels (parentheses, signs and powers)");
        std::uint32_t result = 0;
        if (take('-')) {
            result = push(Node{Op::kNeg, 0, unary(), 0}, column);
        } else if (take('+')) {
            result = unary();
        } else {
            const std::uint32_t base = primary();
            skip_space();
            const std::size_t power_column = pos_ + 1;
            result = take('^') ? binary(Op::kPow, base, unary(), power_column) : base;
        }
        --depth_;
        return result;
    }

    void expect_close(std::size_t open_column) {
        skip_space();
        if (take(')')) return;
        const std::string where = at_end() ? "at the end" : "before " + shown(text_[pos_]);
        fail(pos_ + 1, "expected ')' " + where + " (to close the \"(\" at col " +
                           std::to_string(open_column) + ")");
    }

    std::uint32_t primary() {
        skip_space();
        const std::size_t column = pos_ + 1;
        if (at_end()) fail(column, "expected a number, t, a function or \"(\" at the end");
        const char c = text_[pos_];
        if (c == '(') {
            ++pos_;
            const std::uint32_t inner = expression();
            expect_close(column);
            return inner;
        }
        if (digit(c) || c == '.') return number();
        if (identifier_start(c)) return name();
        fail(column, "expected a number, t, a function or \"(\", got " + shown(c));
    }

    std::uint32_t number() {
        const std::size_t start = pos_;
        while (!at_end() && digit(text_[pos_])) ++pos_;
        if (!at_end() && text_[pos_] == '.') ++pos_;
        while (!at_end() && digit(text_[pos_])) ++pos_;
        if (!at_end() && (text_[pos_] == 'e' || text_[pos_] == 'E')) {
            // After a number "e" always starts an exponent, never the constant: "2e" is an
            // error rather than a silent 2*e.
            std::size_t at = pos_ + 1;
            if (at < text_.size() && (text_[at] == '+' || text_[at] == '-')) ++at;
            if (at >= text_.size() || !digit(text_[at]))
                fail(pos_ + 1, "malformed number: the exponent after \"e\" needs digits");
            pos_ = at;
            while (!at_end() && digit(text_[pos_])) ++pos_;
        }
        const std::string_view digits = text_.substr(start, pos_ - start);
        if (digits == ".") fail(start + 1, "malformed number \".\"");
        double value = 0;
        const auto [end, error] =
            std::from_chars(digits.data(), digits.data() + digits.size(), value);
        if (error != std::errc() || end != digits.data() + digits.size() || !std::isfinite(value))
            fail(start + 1, "number " + std::string(digits) + " is out of range");
        return push(Node{Op::kNumber, value, 0, 0}, start + 1);
    }

    std::uint32_t name() {
        const std::size_t start = pos_;
        while (!at_end() && identifier_char(text_[pos_])) ++pos_;
        const std::string_view id = text_.substr(start, pos_ - start);
        const std::string quoted = "\"" + std::string(id.substr(0, 40)) + "\"";
        skip_space();
        const bool call = !at_end() && text_[pos_] == '(';
        const Function* f = find_function(id);
        if (!call) {
            if (id == "t") return push(Node{Op::kT, 0, 0, 0}, start + 1);
            if (id == "pi") return push(Node{Op::kPi, 0, 0, 0}, start + 1);
            if (id == "e") return push(Node{Op::kE, 0, 0, 0}, start + 1);
            if (f != nullptr)
                fail(start + 1, "function " + quoted + " needs its arguments in parentheses");
            fail(start + 1, "unknown variable " + quoted + " (only t, and the constants pi, e)");
        }
        if (f == nullptr) {
            if (id == "t" || id == "pi" || id == "e")
                fail(start + 1, quoted + " is not a function (write " + std::string(id) +
                                    "*(...) to multiply)");
            fail(start + 1, "unknown function " + quoted + " (" + function_list() + ")");
        }
        const std::size_t open_column = pos_ + 1;
        ++pos_;
        const std::uint32_t first = expression();
        std::uint32_t second = 0;
        int count = 1;
        while (take(',')) {
            second = expression();
            ++count;
        }
        if (count != f->arguments)
            fail(start + 1, std::string(f->name) + " takes " + std::to_string(f->arguments) +
                                (f->arguments == 1 ? " argument" : " arguments") + ", got " +
                                std::to_string(count));
        expect_close(open_column);
        return push(Node{f->op, 0, first, second}, start + 1);
    }

    std::string_view text_;
    std::size_t pos_ = 0;
    int depth_ = 0;
    std::vector<Node> nodes_;
};

}  // namespace

ExpressionError::ExpressionError(std::size_t column, const std::string& message)
    : std::runtime_error("col " + std::to_string(column) + ": " + message),
      column_(column),
      message_(message) {}

Expression parse_expression(std::string_view text) {
    if (text.size() > kMaxExpressionLength)
        throw ExpressionError(kMaxExpressionLength + 1,
                              "expression is " + std::to_string(text.size()) +
                                  " characters long (at most " +
                                  std::to_string(kMaxExpressionLength) + ")");
    return Parser(text).run();
}

}  // namespace pathstream::host::curves
