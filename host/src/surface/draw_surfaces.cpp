// A drawing's surfaces together: one occluder for all of them (each hides the others' lines as
// well as its own), then each wireframe in turn, within the budget.
#include <memory>

#include "pathstream/host/hidden_lines.hpp"
#include "pathstream/host/surface.hpp"

namespace pathstream::host {

double estimated_curves(const SurfaceInput& s) {
    const double per_line = static_cast<double>(s.counts.u + s.counts.v + 2);
    // A parallel is drawn as up to four arcs; a patch's curves are one each.
    return s.revolution ? static_cast<double>(s.revolution->profile.size()) * per_line * 4
                        : static_cast<double>(s.patches.size()) * per_line;
}

std::vector<Subpath> draw_surfaces(const std::vector<SurfaceInput>& surfaces,
                                   const ViewFrame& frame, bool hidden_lines, double tolerance_mm,
                                   const SurfaceBudget& budget, WireframeFigures& figures) {
    double estimate = 0;
    for (std::size_t i = 0; i < surfaces.size(); ++i) {
        estimate += estimated_curves(surfaces[i]);
        if (estimate > static_cast<double>(budget.curves)) {
            throw SurfaceError(i, "more than " + std::to_string(budget.curves) +
                                      " iso-curves (the reader's limit): fewer surfaces or iso "
                                      "lines");
        }
    }
    std::size_t at = 0;
    try {
        std::unique_ptr<Occluder> occluder;
        if (hidden_lines) {
            std::vector<SurfaceSheet> sheets;
            for (at = 0; at < surfaces.size(); ++at) {
                const SurfaceInput& s = surfaces[at];
                for (SurfaceSheet& sheet :
                     s.revolution ? sheets_of(*s.revolution) : sheets_of(s.patches)) {
                    sheets.push_back(std::move(sheet));
                }
            }
            at = 0;
            occluder = std::make_unique<Occluder>(std::move(sheets), frame, 16,
                                                  budget.hidden_line_questions);
        }
        std::vector<Subpath> out;
        std::size_t points = 0;
        std::size_t fit_cells_left = budget.fit_cells;
        for (at = 0; at < surfaces.size(); ++at) {
            const SurfaceInput& s = surfaces[at];
            WireframeFigures f;
            std::vector<Subpath> curves =
                s.revolution ? revolution_wireframe(*s.revolution, s.counts, frame, tolerance_mm,
                                                    &f, occluder.get(), &fit_cells_left)
                             : patch_wireframe(s.patches, s.counts, frame, tolerance_mm, &f,
                                               occluder.get(), &fit_cells_left);
            figures.curves += f.curves;
            figures.exact_curves += f.exact_curves;
            figures.seams_merged += f.seams_merged;
            figures.degenerate += f.degenerate;
            figures.hidden += f.hidden;
            figures.split += f.split;
            for (Subpath& sp : curves) {
                points += sp.points.size();
                out.push_back(std::move(sp));
            }
            if (points > budget.points) {
                throw SurfaceError(at, "the wireframes have more than " +
                                           std::to_string(budget.points) +
                                           " control points (the reader's limit): fewer iso "
                                           "lines");
            }
        }
        return out;
    } catch (const SurfaceError&) {
        throw;
    } catch (const std::domain_error& e) {
        throw SurfaceError(at, e.what());
    } catch (const std::invalid_argument& e) {
        throw SurfaceError(at, e.what());
    } catch (const std::length_error& e) {
        throw SurfaceError(at, e.what());
    }
}

}  // namespace pathstream::host
