// The expression language of function curves ("40*cos(t)"): parsed once into a flat tree that
// evaluate.hpp runs on numbers, intervals and their derivatives.
#pragma once

#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace pathstream::host::curves {

/// Limits that keep hostile text cheap: parsing is linear in the text, evaluation linear in
/// the nodes, and the parser's recursion is bounded by the depth.
inline constexpr std::size_t kMaxExpressionLength = 4096;
inline constexpr int kMaxExpressionDepth = 64;
inline constexpr std::size_t kMaxExpressionNodes = 1024;

/// A malformed expression. what() is "col N: message"; column() is N, 1-based in the text.
class ExpressionError : public std::runtime_error {
public:
    ExpressionError(std::size_t column, const std::string& message);
    std::size_t column() const { return column_; }
    /// The message without its "col N: " prefix.
    const std::string& message() const { return message_; }

private:
    std::size_t column_;
    std::string message_;
};

/// What a node computes. Unary operations read `a`; binary ones `a` and `b`.
enum class Op : std::uint8_t {
    kNumber,  // `value`
    kT,       // the parameter
    kPi,
    kE,
    kNeg,
    kAdd,
    kSub,
    kMul,
    kDiv,
    kPow,  // also pow(a, b)
    kSin,
    kCos,
    kTan,
    kAsin,
    kAcos,
    kAtan,
    kAtan2,  // atan2(a = y, b = x)
    kSqrt,
    kExp,
    kLn,
    kLog10,
    kAbs,
    kSinh,
    kCosh,
    kTanh,
    kMin,
    kMax,
    kHypot,
    kFresnelC,
    kFresnelS,
};

/// One node. Children always come before their parent in Expression::nodes.
struct Node {
    Op op = Op::kNumber;
    double value = 0;     ///< kNumber only
    std::uint32_t a = 0;  ///< first operand's index
    std::uint32_t b = 0;  ///< second operand's index
};

/// A parsed expression: nodes in post-order (operands first), the last one the result, so an
/// evaluation is one pass over the vector.
struct Expression {
    std::vector<Node> nodes;
    std::string text;  ///< what it was parsed from, for messages
};

/// Parses `text` (grammar and functions in docs/parametric-curves.md). O(text length).
/// Throws ExpressionError naming the column: "empty expression", "expected ')'", "unknown
/// function \"sine\" (...)", "unknown variable \"x\" (only t)", a wrong argument count, a
/// number out of range, and one message each for text longer than kMaxExpressionLength,
/// nesting deeper than kMaxExpressionDepth and more than kMaxExpressionNodes nodes.
Expression parse_expression(std::string_view text);

}  // namespace pathstream::host::curves
