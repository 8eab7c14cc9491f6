// The Bezier patch text form: whitespace-separated numbers, read token by token with their
// line and column so that every error names its place.
#include <charconv>
#include <cmath>
#include <limits>

#include "pathstream/host/bpt_path.hpp"
#include "pathstream/machine/input_error.hpp"

namespace pathstream::host {
namespace {

constexpr std::size_t kMaxPatches = 100'000;

class Tokens {
public:
    Tokens(const std::string& text, const std::string& file) : text_(text), file_(file) {}

    /// The next token, or false at the end; `at` is where it starts.
    bool next(std::string_view& token, SourceLocation& at) {
        while (pos_ < text_.size() && std::isspace(static_cast<unsigned char>(text_[pos_]))) {
            advance();
        }
        if (pos_ >= text_.size()) return false;
        at = {line_, column_};
        const std::size_t start = pos_;
        while (pos_ < text_.size() && !std::isspace(static_cast<unsigned char>(text_[pos_]))) {
            advance();
        }
        token = std::string_view(text_).substr(start, pos_ - start);
        return true;
    }

    double number(const char* what) {
        std::string_view t;
        SourceLocation at;
        if (!next(t, at)) throw InputError(file_, {line_, column_}, std::string("missing ") + what);
        double v = 0;
        const auto [end, ec] = std::from_chars(t.data(), t.data() + t.size(), v);
        if (ec != std::errc() || end != t.data() + t.size() || !std::isfinite(v)) {
            throw InputError(file_, at,
                             std::string(what) + " must be a finite number, got \"" +
                                 std::string(t.substr(0, 40)) + "\"");
        }
        last_ = at;
        return v;
    }

    long whole(const char* what, long lo, long hi) {
        const double v = number(what);
        if (v != std::floor(v) || v < static_cast<double>(lo) || v > static_cast<double>(hi)) {
            throw InputError(file_, last_,
                             std::string(what) + " must be a whole number from " +
                                 std::to_string(lo) + " to " + std::to_string(hi));
        }
        return static_cast<long>(v);
    }

    const SourceLocation& last() const { return last_; }

private:
    void advance() {
        if (text_[pos_] == '\n') {
            ++line_;
            column_ = 1;
        } else {
            ++column_;
        }
        ++pos_;
    }

    const std::string& text_;
    const std::string& file_;
    std::size_t pos_ = 0, line_ = 1, column_ = 1;
    SourceLocation last_{};
};

}  // namespace

Path parse_bpt_path(const std::string& text, const std::string& file, const BptOptions& options) {
    const ViewFrame frame = view_frame(options.view);
    Tokens tokens(text, file);
    const auto count = static_cast<std::size_t>(
        tokens.whole("the patch count", 1, static_cast<long>(kMaxPatches)));
    SurfaceInput surface;
    surface.counts = options.counts;
    for (std::size_t i = 0; i < count; ++i) {
        BezierPatch patch;
        patch.degree_u = static_cast<int>(tokens.whole("a patch's u degree", 1, 3));
        patch.location = tokens.last();
        patch.degree_v = static_cast<int>(tokens.whole("a patch's v degree", 1, 3));
        const int points = (patch.degree_u + 1) * (patch.degree_v + 1);
        for (int k = 0; k < points; ++k) {
            Point3 p;
            for (double& c : p) {
                c = tokens.number("a coordinate");
                if (std::abs(c) > 1e6) {
                    throw InputError(file, tokens.last(),
                                     "coordinate is out of range (|value| <= 1e6 mm)");
                }
            }
            patch.points.push_back(p);
        }
        surface.patches.push_back(std::move(patch));
    }
    std::string_view extra;
    SourceLocation at;
    if (tokens.next(extra, at)) {
        throw InputError(file, at,
                         "data after the " + std::to_string(count) + " patches the file announces");
    }
    WireframeFigures figures;
    Path path;
    path.axes = 2;
    try {
        path.subpaths = draw_surfaces({surface}, frame, options.hidden_lines, options.tolerance_mm,
                                      options.budget, figures);
    } catch (const SurfaceError& e) {
        throw InputError(file, {}, e.what());
    }
    if (path.subpaths.empty()) throw InputError(file, {}, "the patches draw no curve");
    return path;
}

}  // namespace pathstream::host
