// One template walks the nodes for both number types; the few rules that differ between a
// point and an interval (constants, kinks) are overloads below.
#include "evaluate.hpp"

#include <cmath>
#include <vector>

#include "fresnel.hpp"

namespace pathstream::host::curves {

namespace {

double sqr(double x) {
    return x * x;
}

bool is_zero(double x) {
    return x == 0;
}

bool is_zero(const Interval& x) {
    return x.lo == 0 && x.hi == 0;
}

double pi_of(double) {
    return M_PI;
}

Interval pi_of(const Interval&) {
    return pi_interval();
}

double e_of(double) {
    return M_E;
}

Interval e_of(const Interval&) {
    return e_interval();
}

double ln10_of(double) {
    return M_LN10;
}

Interval ln10_of(const Interval&) {
    return log(Interval(10.0));
}

double minus_one(double x) {
    return x - 1;
}

// An integer exponent stays a point (outward rounding would make x^(n-1) a real power, undefined
// for negative x).
Interval minus_one(const Interval& x) {
    if (x.lo == x.hi && std::trunc(x.lo) == x.lo && std::fabs(x.lo) < 0x1p52) return x.lo - 1;
    return x - Interval(1.0);
}

double sign(double x) {
    return (x > 0) - (x < 0);
}

// min(a, b) with its derivative: the smaller operand's, or both slopes' hull where the
// operands may cross.
Dual<double> smaller(const Dual<double>& a, const Dual<double>& b) {
    return a.v <= b.v ? a : b;
}

Dual<Interval> smaller(const Dual<Interval>& a, const Dual<Interval>& b) {
    if (a.v.hi < b.v.lo) return a;
    if (b.v.hi < a.v.lo) return b;
    return {fmin(a.v, b.v), hull(a.d, b.d)};
}

template <class N>
Dual<N> negate(const Dual<N>& a) {
    return {-a.v, -a.d};
}

template <class N>
Dual<N> larger(const Dual<N>& a, const Dual<N>& b) {
    return negate(smaller(negate(a), negate(b)));
}

template <class N>
Dual<N> power(const Dual<N>& a, const Dual<N>& b) {
    using std::log;
    using std::pow;
    const N v = pow(a.v, b.v);
    if (is_zero(b.v) && is_zero(b.d)) return {v, N(0.0)};
    N d = b.v * pow(a.v, minus_one(b.v)) * a.d;
    if (!is_zero(b.d)) d = d + v * log(a.v) * b.d;
    return {v, d};
}

template <class N>
Dual<N> apply(const Node& n, const Dual<N>& a, const Dual<N>& b, const N& t) {
    using std::acos, std::asin, std::atan, std::atan2, std::cos, std::cosh, std::exp, std::fabs,
        std::hypot, std::log, std::log10, std::sin, std::sinh, std::sqrt, std::tan, std::tanh;
    const N one(1.0);
    switch (n.op) {
        case Op::kNumber:
            return {N(n.value), N(0.0)};
        case Op::kT:
            return {t, one};
        case Op::kPi:
            return {pi_of(t), N(0.0)};
        case Op::kE:
            return {e_of(t), N(0.0)};
        case Op::kNeg:
            return negate(a);
        case Op::kAdd:
            return {a.v + b.v, a.d + b.d};
        case Op::kSub:
            return {a.v - b.v, a.d - b.d};
        case Op::kMul:
            return {a.v * b.v, a.d * b.v + a.v * b.d};
        case Op::kDiv: {
            const N v = a.v / b.v;
            return {v, (a.d - v * b.d) / b.v};
        }
        case Op::kPow:
            return power(a, b);
        case Op::kSin:
            return {sin(a.v), cos(a.v) * a.d};
        case Op::kCos:
            return {cos(a.v), -(sin(a.v) * a.d)};
        case Op::kTan: {
            const N v = tan(a.v);
            return {v, (one + sqr(v)) * a.d};
        }
        case Op::kAsin:
            return {asin(a.v), a.d / sqrt(one - sqr(a.v))};
        case Op::kAcos:
            return {acos(a.v), -(a.d / sqrt(one - sqr(a.v)))};
        case Op::kAtan:
            return {atan(a.v), a.d / (one + sqr(a.v))};
        case Op::kAtan2:
            return {atan2(a.v, b.v), (b.v * a.d - a.v * b.d) / (sqr(a.v) + sqr(b.v))};
        case Op::kSqrt: {
            const N v = sqrt(a.v);
            return {v, a.d / (N(2.0) * v)};
        }
        case Op::kExp: {
            const N v = exp(a.v);
            return {v, v * a.d};
        }
        case Op::kLn:
            return {log(a.v), a.d / a.v};
        case Op::kLog10:
            return {log10(a.v), a.d / (a.v * ln10_of(t))};
        case Op::kAbs:
            return {fabs(a.v), sign(a.v) * a.d};
        case Op::kSinh:
            return {sinh(a.v), cosh(a.v) * a.d};
        case Op::kCosh:
            return {cosh(a.v), sinh(a.v) * a.d};
        case Op::kTanh: {
            const N v = tanh(a.v);
            return {v, (one - sqr(v)) * a.d};
        }
        case Op::kMin:
            return smaller(a, b);
        case Op::kMax:
            return larger(a, b);
        case Op::kHypot: {
            const N v = hypot(a.v, b.v);
            return {v, (a.v * a.d + b.v * b.d) / v};
        }
        case Op::kFresnelC:
            return {fresnel_c(a.v), cos(pi_of(t) * sqr(a.v) / N(2.0)) * a.d};
        case Op::kFresnelS:
            return {fresnel_s(a.v), sin(pi_of(t) * sqr(a.v) / N(2.0)) * a.d};
    }
    return {};
}

template <class N>
Dual<N> run(const Expression& e, const N& t) {
    if (e.nodes.empty()) return {};
    std::vector<Dual<N>> values(e.nodes.size());
    for (std::size_t i = 0; i < e.nodes.size(); ++i) {
        const Node& n = e.nodes[i];
        values[i] = apply(n, values[n.a], values[n.b], t);
    }
    return values.back();
}

}  // namespace

double evaluate(const Expression& e, double t) {
    return run(e, t).v;
}

Dual<double> evaluate_dual(const Expression& e, double t) {
    return run(e, t);
}

Dual<Interval> evaluate_dual(const Expression& e, const Interval& t) {
    return run(e, t);
}

}  // namespace pathstream::host::curves
