// The function-curve expression language (host/src/curves): parsing and its messages, point
// evaluation, the Fresnel integrals against reference values, and interval enclosures that
// must contain every point sample (a seeded property test).
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <random>
#include <string>

#include "curves/evaluate.hpp"
#include "curves/expression.hpp"
#include "curves/fresnel.hpp"

using namespace pathstream::host::curves;

namespace {

double at(const std::string& text, double t) {
    return evaluate(parse_expression(text), t);
}

// The error's column and message, or 0 and "" when `text` parses.
std::pair<std::size_t, std::string> error_of(const std::string& text) {
    try {
        parse_expression(text);
    } catch (const ExpressionError& e) {
        return {e.column(), e.what()};
    }
    return {0, ""};
}

}  // namespace

TEST_CASE("expressions follow the usual precedence", "[function]") {
    CHECK(at("-t^2", 3) == -9);
    CHECK(at("2^3^2", 0) == 512);
    CHECK(at("2^-1", 0) == 0.5);
    CHECK(at("8/2/2", 0) == 2);
    CHECK(at("2-3-4", 0) == -5);
    CHECK(at("1+2*3", 0) == 7);
    CHECK(at("(1+2)*3", 0) == 9);
    CHECK(at("1e-3*t", 2000) == Approx(2));
    CHECK(at(".5 + 2.E1 + 3e+1", 0) == 50.5);
    CHECK(at("--t", 4) == 4);
    CHECK(at("pi", 0) == M_PI);
    CHECK(at("e", 0) == M_E);
    CHECK(at(" atan2(1, -1) ", 0) == Approx(3 * M_PI / 4));
    CHECK(at("min(t, 2) + max(t, 2) + pow(t, 2) + hypot(3, 4)", 5) == Approx(37));
    CHECK(at("ln(e) + log10(1000) + exp(0) + sqrt(16) + abs(-2)", 0) == Approx(11));
    CHECK(at("sinh(1) - (exp(1) - exp(-1)) / 2", 0) == Approx(0).margin(1e-15));
    CHECK(at("fresnel_c(1) + fresnel_s(1)", 0) == Approx(0.7798934003768228 + 0.4382591473903548));
}

TEST_CASE("expression errors name the column", "[function]") {
    using Catch::Matchers::Contains;
    const auto check = [](const std::string& text, std::size_t column, const std::string& part) {
        const auto [col, what] = error_of(text);
        INFO(text << " -> " << what);
        CHECK(col == column);
        CHECK_THAT(what, Contains(part));
        CHECK_THAT(what, Contains("col " + std::to_string(column) + ": "));
    };
    check("", 1, "empty expression");
    check("   ", 1, "empty expression");
    check("40*sine(t)", 4, "unknown function \"sine\" (sin cos tan");
    check("(t", 3, "expected ')'");
    check("sin(t", 6, "expected ')' at the end");
    check("x + 1", 1, "unknown variable \"x\" (only t");
    check("2t", 2, "expected an operator before \"t\"");
    check("t+", 3, "expected a number, t, a function or \"(\" at the end");
    check("t)", 2, "no \"(\" to close");
    check("atan2(t)", 1, "atan2 takes 2 arguments, got 1");
    check("sin(t, 1)", 1, "sin takes 1 argument, got 2");
    check("t*1e999", 3, "number 1e999 is out of range");
    check("2e", 2, "exponent");
    check("sin t", 1, "needs its arguments in parentheses");
    check("t(2)", 1, "is not a function");
    check("t # 2", 3, "expected an operator before \"#\"");
    check("1 + \x01", 5, "byte 0x01");
}

TEST_CASE("expression limits each have their own message", "[function]") {
    using Catch::Matchers::Contains;
    const auto [col1, long_text] = error_of(std::string(kMaxExpressionLength + 1, '1'));
    CHECK(col1 == kMaxExpressionLength + 1);
    CHECK_THAT(long_text, Contains("characters long (at most 4096)"));
    CHECK(error_of(std::string(kMaxExpressionLength - 1, ' ') + "t").first == 0);

    const int deep = kMaxExpressionDepth + 5;
    const auto [col2, nested] = error_of(std::string(deep, '(') + "t" + std::string(deep, ')'));
    CHECK(col2 > 1);
    CHECK_THAT(nested, Contains("nested deeper than 64 levels"));
    CHECK_THAT(error_of(std::string(200, '-') + "t").second, Contains("nested deeper"));
    CHECK(error_of(std::string(30, '(') + "t" + std::string(30, ')')).first == 0);

    std::string sum = "t";
    for (std::size_t i = 0; i < kMaxExpressionNodes; ++i) sum += "+t";
    const auto [col3, many] = error_of(sum);
    CHECK(col3 > 1000);
    CHECK_THAT(many, Contains("more than 1024 nodes"));
}

TEST_CASE("Fresnel integrals match reference values", "[function]") {
    // C(x), S(x) to 17 digits (arbitrary-precision evaluation), both sides of the switch from
    // the series to the asymptotic expansion at 4.7.
    const struct {
        double x, c, s;
    } known[] = {
        {0.5, 0.49234422587144639, 0.064732432859999278},
        {1, 0.7798934003768228, 0.4382591473903548},
        {2, 0.48825340607534075, 0.34341567836369824},
        {3, 0.60572078929768563, 0.49631299896737504},
        {5, 0.56363118870401223, 0.49919138191711689},
        {10, 0.49989869420551572, 0.46816997858488224},
        {100, 0.4999998986788179, 0.49681690114783755},
    };
    for (const auto& k : known) {
        INFO("x = " << k.x);
        CHECK(std::fabs(fresnel_c(k.x) - k.c) < 1e-15);
        CHECK(std::fabs(fresnel_s(k.x) - k.s) < 1e-15);
        CHECK(fresnel_c(-k.x) == -fresnel_c(k.x));
    }
    CHECK(fresnel_c(0.0) == 0);
    CHECK(fresnel_c(INFINITY) == 0.5);
    CHECK(fresnel_s(-INFINITY) == -0.5);
    CHECK(std::fabs(fresnel_c(1e8) - 0.5) < 1e-8);
    // Past 2^53 x² is an even integer: the phase reduction must not leave a huge remainder.
    CHECK(std::fabs(fresnel_s(7.6e49) - 0.5) < 1e-15);
    CHECK(std::fabs(fresnel_c(-3.3e30) + 0.5) < 1e-15);
    // Continuity across the switch.
    CHECK(std::fabs(fresnel_c(std::nextafter(4.7, 0.0)) - fresnel_c(4.7)) < 1e-14);
    CHECK(std::fabs(fresnel_s(std::nextafter(4.7, 0.0)) - fresnel_s(4.7)) < 1e-14);
}

TEST_CASE("interval functions handle their hard cases", "[function]") {
    CHECK(sin(Interval(0, 2)).hi == 1);
    CHECK(sin(Interval(4, 5)).lo == -1);
    CHECK(cos(Interval(3, 3.5)).lo == -1);
    CHECK(cos(Interval(-0.1, 0.1)).hi == 1);
    CHECK(sin(Interval(0.1, 1)).hi < 1);
    CHECK(sin(Interval(1, 1e12)).lo == -1);
    CHECK(!tan(Interval(1.5, 1.7)).bounded());
    CHECK(tan(Interval(-1, 1)).bounded());
    CHECK(!(Interval(1) / Interval(-1, 1)).bounded());
    CHECK(sqrt(Interval(-1, 1)).undefined());
    CHECK(log(Interval(-1, 2)).undefined());
    CHECK(asin(Interval(0, 1.5)).undefined());
    CHECK(sqr(Interval(-2, 1)).lo == 0);
    CHECK(integer_power(Interval(-2, 1), 3).lo <= -8);
    CHECK(pow(Interval(-2, -1), Interval(2)).contains(4));
    CHECK(pow(Interval(-2, -1), Interval(0.5)).undefined());
    CHECK(atan2(Interval(-1, 1), Interval(-2, -1)).hi >= M_PI);
    CHECK(atan2(Interval(1, 2), Interval(1, 2)).contains(M_PI / 4));
    CHECK(fresnel_c(Interval(0.9, 1.1)).contains(0.7798934003768228));
    CHECK(fresnel_s(Interval(-1e3, 1e3)).hi < 0.8);
    // Directed rounding: the exact sum 1 + 1e-30 lies between 1 and the next double up; exact
    // results stay points.
    const Interval sum = Interval(1) + Interval(1e-30);
    CHECK(sum.lo == 1);
    CHECK(sum.hi == std::nextafter(1.0, 2.0));
    CHECK((Interval(1) - Interval(1e-30)).lo == std::nextafter(1.0, 0.0));
    const Interval third = Interval(1) / Interval(3);
    CHECK(third.lo < 1.0 / 3);
    CHECK(third.hi > 1.0 / 3);
    CHECK((Interval(0.1) * Interval(3)).contains(0.1 * 3));
    CHECK((Interval(0) * Interval(3)).hi == 0);
    CHECK((Interval(-1) * Interval(3)).lo == -3);
    CHECK((Interval(0) - Interval(0)).hi == 0);
    CHECK((Interval(1e-200) * Interval(1e-200)).lo < 0);  // underflowed to 0: still stepped
    CHECK((Interval(-INFINITY, 0) + Interval(1)).lo == -INFINITY);
    CHECK(!(Interval(0, INFINITY) * Interval(0)).bounded());
    const Interval pi = pi_interval();
    CHECK(pi.lo < M_PI);
    CHECK(pi.hi > M_PI);
}

namespace {

// A random expression over t of about `depth` levels, from every operation the language has.
std::string random_expression(std::mt19937_64& rng, int depth) {
    std::uniform_int_distribution<int> pick(0, 99);
    const auto sub = [&] { return random_expression(rng, depth - 1); };
    if (depth <= 0 || pick(rng) < 15) {
        switch (pick(rng) % 4) {
            case 0:
                return std::to_string(std::uniform_real_distribution<double>(-3, 3)(rng));
            case 1:
                return "pi";
            default:
                return "t";
        }
    }
    static const char* const kUnary[] = {"sin",  "cos",   "tan",       "asin",     "acos", "atan",
                                         "sqrt", "exp",   "ln",        "abs",      "sinh", "cosh",
                                         "tanh", "log10", "fresnel_c", "fresnel_s"};
    static const char* const kBinary[] = {"atan2", "min", "max", "pow", "hypot"};
    static const char* const kOperators[] = {"+", "-", "*", "/", "^"};
    const int kind = pick(rng) % 4;
    if (kind == 0) return std::string(kUnary[pick(rng) % 16]) + "(" + sub() + ")";
    if (kind == 1) return std::string(kBinary[pick(rng) % 5]) + "(" + sub() + ", " + sub() + ")";
    if (kind == 2) return "-(" + sub() + ")";
    const char* op = kOperators[pick(rng) % 5];
    if (op[0] == '^') return "(" + sub() + ")^" + std::to_string(pick(rng) % 5 - 1);
    return "(" + sub() + ")" + op + "(" + sub() + ")";
}

bool inside(double x, const Interval& enclosure) {
    // The point value has rounding errors of its own; the enclosure holds the exact value.
    const double slack = 1e-9 * (1 + std::fabs(x));
    return enclosure.lo - slack <= x && x <= enclosure.hi + slack;
}

}  // namespace

TEST_CASE("interval enclosures contain every point sample", "[function]") {
    // Seed: Catch's --rng-seed (a fixed default without it); size: PATHSTREAM_FUNCTION_CASES.
    const unsigned seed = Catch::rngSeed() != 0 ? Catch::rngSeed() : 20261129u;
    const char* env = std::getenv("PATHSTREAM_FUNCTION_CASES");
    const int cases = env != nullptr ? std::atoi(env) : 400;
    std::mt19937_64 rng(seed);
    std::size_t checked = 0, bounded = 0;
    for (int c = 0; c < cases; ++c) {
        const std::string text = random_expression(rng, 4);
        const Expression e = parse_expression(text);
        for (int k = 0; k < 10; ++k) {
            const double lo = std::uniform_real_distribution<double>(-6, 6)(rng);
            const double width = std::pow(10.0, std::uniform_real_distribution<double>(-6, 1)(rng));
            const Interval cell(lo, lo + width);
            const Dual<Interval> enclosure = evaluate_dual(e, cell);
            if (enclosure.v.undefined()) continue;
            for (int s = 0; s <= 20; ++s) {
                const double t = s == 20 ? cell.hi : cell.lo + width * s / 20;
                const Dual<double> point = evaluate_dual(e, t);
                INFO("seed " << seed << ": " << text << " over [" << cell.lo << ", " << cell.hi
                             << "] at t = " << t);
                if (std::isfinite(point.v)) {
                    ++checked;
                    bounded += enclosure.v.bounded();
                    REQUIRE(inside(point.v, enclosure.v));
                }
                if (std::isfinite(point.d) && !enclosure.d.undefined())
                    REQUIRE(inside(point.d, enclosure.d));
            }
        }
    }
    // Not vacuous: most samples met a finite enclosure.
    CHECK(checked > static_cast<std::size_t>(cases) * 40);
    CHECK(bounded > checked / 2);
}
