// Evaluating an Expression on numbers and on intervals, with forward-mode derivatives: the
// value of a curve coordinate and its slope at a point, or enclosures of both over an
// interval of the parameter.
#pragma once

#include "expression.hpp"
#include "interval.hpp"

namespace pathstream::host::curves {

/// A value and its derivative with respect to t.
template <class N>
struct Dual {
    N v{};
    N d{};
};

/// The expression at t. One pass over the nodes; never throws (NaN or infinity where the
/// expression is undefined or overflows).
double evaluate(const Expression& e, double t);
/// The expression and its derivative at t, as evaluate. Where a function has a kink (abs,
/// min, max) the derivative is one of the one-sided ones or 0.
Dual<double> evaluate_dual(const Expression& e, double t);
/// Intervals containing the expression's values and derivatives for every t in `t` (at a
/// kink: the slopes on either side and everything between, which is what the mean-value
/// bound of a Lipschitz function needs). Unbounded or undefined (see Interval) where nothing
/// better is known. One pass over the nodes; never throws.
Dual<Interval> evaluate_dual(const Expression& e, const Interval& t);

}  // namespace pathstream::host::curves
