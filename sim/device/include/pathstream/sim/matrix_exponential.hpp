// The exponential of a square matrix: how the simulator's linear plants are discretized
// exactly (a system held constant over a tick advances by exp(A T)).
#pragma once

#include <cstddef>
#include <vector>

namespace pathstream::sim {

/// A dense square matrix of doubles, row-major.
class SquareMatrix {
public:
    /// The n x n zero matrix.
    explicit SquareMatrix(std::size_t n) : n_(n), values_(n * n, 0.0) {}

    /// The n x n identity.
    static SquareMatrix identity(std::size_t n);

    std::size_t size() const { return n_; }  ///< n
    /// Element (row, column), both < size(); not checked.
    double& operator()(std::size_t row, std::size_t column) { return values_[row * n_ + column]; }
    double operator()(std::size_t row, std::size_t column) const {
        return values_[row * n_ + column];
    }

private:
    std::size_t n_;
    std::vector<double> values_;
};

/// The matrix product a b. Throws std::invalid_argument when the sizes differ. O(n^3).
SquareMatrix multiply(const SquareMatrix& a, const SquareMatrix& b);

/// exp(a) = sum over k of a^k / k!, by scaling and squaring: a is divided by 2^s until its
/// 1-norm (largest absolute column sum) is at most 1/2, the Taylor series of the scaled matrix
/// is summed to 20 terms (truncation below 1e-25 relative to its norm) and the result is
/// squared s times. Accurate to a few ulps times the condition of the squarings: for the
/// plants here (damped modes, norm of a up to ~1e5) about 1e-12 relative. Throws
/// std::invalid_argument when an element of a is not finite. O(n^3 (20 + s)).
SquareMatrix matrix_exponential(const SquareMatrix& a);

}  // namespace pathstream::sim
