#include "pathstream/sim/matrix_exponential.hpp"

#include <cmath>
#include <stdexcept>

namespace pathstream::sim {

SquareMatrix SquareMatrix::identity(std::size_t n) {
    SquareMatrix m(n);
    for (std::size_t i = 0; i < n; ++i) m(i, i) = 1;
    return m;
}

SquareMatrix multiply(const SquareMatrix& a, const SquareMatrix& b) {
    if (a.size() != b.size()) throw std::invalid_argument("matrix sizes differ");
    const std::size_t n = a.size();
    SquareMatrix c(n);
    for (std::size_t i = 0; i < n; ++i)
        for (std::size_t k = 0; k < n; ++k) {
            const double aik = a(i, k);
            if (aik == 0) continue;
            for (std::size_t j = 0; j < n; ++j) c(i, j) += aik * b(k, j);
        }
    return c;
}

SquareMatrix matrix_exponential(const SquareMatrix& a) {
    const std::size_t n = a.size();
    double norm = 0;
    for (std::size_t j = 0; j < n; ++j) {
        double column = 0;
        for (std::size_t i = 0; i < n; ++i) {
            if (!std::isfinite(a(i, j)))
                throw std::invalid_argument("matrix exponential of a matrix that is not finite");
            column += std::fabs(a(i, j));
        }
        norm = std::fmax(norm, column);
    }
    int squarings = 0;
    while (norm > 0.5) {
        norm /= 2;
        ++squarings;
    }
    const double scale = std::ldexp(1.0, -squarings);
    SquareMatrix scaled = a;
    for (std::size_t i = 0; i < n; ++i)
        for (std::size_t j = 0; j < n; ++j) scaled(i, j) *= scale;
    SquareMatrix sum = SquareMatrix::identity(n);
    SquareMatrix term = SquareMatrix::identity(n);
    for (int k = 1; k <= 20; ++k) {
        term = multiply(term, scaled);
        for (std::size_t i = 0; i < n; ++i)
            for (std::size_t j = 0; j < n; ++j) {
                term(i, j) /= k;
                sum(i, j) += term(i, j);
            }
    }
    for (int i = 0; i < squarings; ++i) sum = multiply(sum, sum);
    return sum;
}

}  // namespace pathstream::sim
