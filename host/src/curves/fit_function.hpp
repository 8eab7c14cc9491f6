// Curves given as functions of a parameter ("x": "40*cos(t)", ...) as open cubic Bezier chains
// proven to stay within a tolerance of the function at the same parameter.
#pragma once

#include <cstddef>
#include <stdexcept>
#include <string>
#include <vector>

#include "expression.hpp"
#include "pathstream/host/point_list.hpp"

namespace pathstream::host::curves {

/// A curve t -> (coordinates[0](t), coordinates[1](t), ...) for t in [t0, t1], in mm.
struct FunctionCurve {
    std::vector<Expression> coordinates;  ///< 1 to 8 (2 or 3 from a path file)
    double t0 = 0;
    double t1 = 1;
};

/// What a fit cost and what it proved.
struct FitFigures {
    std::size_t pieces = 0;
    std::size_t cells = 0;             ///< interval cells evaluated, failed attempts included
    double largest_bound = 0;          ///< the largest proven error bound of a piece (mm)
    double largest_sampled_error = 0;  ///< the largest error seen at the fitter's samples (mm)
};

/// Budgets that bound a fit's time whatever the input (each exceeded one is its own FitError).
struct FitLimits {
    std::size_t max_pieces = 200'000;
    std::size_t max_cells = 50'000'000;      ///< over the whole fit
    std::size_t max_cells_per_piece = 4096;  ///< before the piece is halved instead
};

/// A fit that cannot be done; what() says why and where (the t).
class FitError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

/// A fitted chain with what lies behind it.
struct FittedCurve {
    std::vector<PathPoint> points;  ///< P0 C C P1 C C P2 ... : 3 × pieces + 1 points
    std::vector<double> breaks;     ///< the t of each on-curve point: pieces + 1 values
    std::vector<double> bounds;     ///< per piece: the proven bound of its error (mm)
    FitFigures figures;
};

/// Fits `curve` with cubic Hermite pieces (ends and end slopes from the curve; inner control
/// points at a third of the piece's parameter length along the slopes), halving a piece until
/// prove_piece shows it within `tolerance_mm` of the curve at the same parameter: piece k over
/// [breaks[k], breaks[k+1]] is reached at u = (t - breaks[k]) / (breaks[k+1] - breaks[k]).
/// Cost: O(cells × nodes), at most `limits`. Throws FitError for a t range that is not finite
/// or does not increase, a tolerance that is not positive, a coordinate or slope that is not
/// finite at a t the fit needs ("... at t=0"), an error that cannot be bounded because the
/// slope is unbounded near some t, and each exceeded limit.
FittedCurve fit_function_curve_pieces(const FunctionCurve& curve, double tolerance_mm,
                                      const FitLimits& limits = {});

/// The chain alone (as nurbs_to_bezier returns one): fit_function_curve_pieces(...).points,
/// its figures copied to `figures` when given. Throws as fit_function_curve_pieces.
std::vector<PathPoint> fit_function_curve(const FunctionCurve& curve, double tolerance_mm,
                                          FitFigures* figures = nullptr,
                                          const FitLimits& limits = {});

}  // namespace pathstream::host::curves
