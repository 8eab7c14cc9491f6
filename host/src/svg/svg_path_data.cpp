// Path data (the d attribute) to cubic pieces: every SVG 2 command, absolute and relative.
#include <cstring>

#include "pathstream/host/svg_path.hpp"

namespace pathstream::host::svg {
namespace {

bool is_letter(char c) {
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z');
}

char upper(char c) {
    return (c >= 'a' && c <= 'z') ? static_cast<char>(c - 'a' + 'A') : c;
}

Point reflect(Point control, Point about) {
    return {2 * about.x - control.x, 2 * about.y - control.y};
}

class PathData {
public:
    PathData(std::string_view d, const Affine& to_mm, double tolerance_mm)
        : s_(d, "path data"), to_mm_(to_mm), tolerance_mm_(tolerance_mm) {}

    CubicSubpaths parse() {
        char command = 0;
        while (!s_.at_end()) {
            const char c = s_.peek();
            const std::size_t at = s_.position();
            if (is_letter(c)) {
                if (!std::strchr("MmLlHhVvCcSsQqTtAaZz", c)) {
                    s_.fail(std::string("unknown command '") + c + "'", at);
                }
                if (command == 0 && upper(c) != 'M') {
                    s_.fail(std::string("must start with a moveto ('M' or 'm'), found '") + c + "'",
                            at);
                }
                command = written_ = c;
                s_.advance();
                s_.skip_space();
            } else if (s_.number_ahead() || c == ',') {
                if (command == 0) {
                    s_.fail(std::string("must start with a moveto ('M' or 'm'), found ") +
                                (c == ',' ? "','" : "a number"),
                            at);
                }
                if (c == ',') s_.fail(std::string("unexpected ',' after '") + written_ + "'", at);
                if (upper(command) == 'Z') {
                    s_.fail(
                        std::string("unexpected number after '") + written_ + "' (it takes none)",
                        at);
                }
            } else {
                s_.fail(std::string("unexpected character '") + c + "'", at);
            }
            execute(command);
            // After a moveto, further coordinate pairs are implicit linetos.
            if (command == 'M') command = 'L';
            if (command == 'm') command = 'l';
        }
        return std::move(out_);
    }

private:
    // Messages name the command letter as written (an implicit lineto after 'M' says 'M').
    double number() {
        const double v = s_.number(std::string("'") + written_ + "'");
        s_.skip_comma_space();
        return v;
    }

    bool flag() {
        const bool v = s_.flag(std::string("'") + written_ + "'");
        s_.skip_comma_space();
        return v;
    }

    Point point(bool relative) {
        const double x = number();
        const double y = number();
        return relative ? Point{current_.x + x, current_.y + y} : Point{x, y};
    }

    void add(const Cubic& c) {
        if (!open_) {
            out_.emplace_back();
            open_ = true;
        }
        out_.back().push_back(c);
    }

    void execute(char command) {
        const bool rel = command >= 'a';
        const char kind = upper(command);
        switch (kind) {
            case 'M': {
                const Point p = point(rel);
                out_.emplace_back();
                open_ = true;
                current_ = start_ = p;
                break;
            }
            case 'L':
                line_to(point(rel));
                break;
            case 'H': {
                const double x = number();
                line_to({rel ? current_.x + x : x, current_.y});
                break;
            }
            case 'V': {
                const double y = number();
                line_to({current_.x, rel ? current_.y + y : y});
                break;
            }
            case 'C': {
                const Point c1 = point(rel), c2 = point(rel), p = point(rel);
                cubic_to(c1, c2, p);
                break;
            }
            case 'S': {
                const Point c1 = (previous_ == 'C' || previous_ == 'S')
                                     ? reflect(last_control_, current_)
                                     : current_;
                const Point c2 = point(rel), p = point(rel);
                cubic_to(c1, c2, p);
                break;
            }
            case 'Q': {
                const Point q = point(rel), p = point(rel);
                quadratic_to(q, p);
                break;
            }
            case 'T': {
                const Point q = (previous_ == 'Q' || previous_ == 'T')
                                    ? reflect(last_control_, current_)
                                    : current_;
                quadratic_to(q, point(rel));
                break;
            }
            case 'A': {
                const double rx = number(), ry = number(), angle = number();
                const bool large = flag(), sweep = flag();
                const Point p = point(rel);
                for (const Cubic& c : arc_to_cubics(current_, rx, ry, angle, large, sweep, p,
                                                    to_mm_, tolerance_mm_)) {
                    add(c);
                }
                current_ = p;
                break;
            }
            default: {  // 'Z'
                if (open_ && !(current_ == start_)) add(line_cubic(current_, start_));
                open_ = false;  // a drawing command after Z starts a new subpath at start_
                current_ = start_;
                break;
            }
        }
        previous_ = kind;
    }

    void line_to(Point p) {
        add(line_cubic(current_, p));
        current_ = p;
    }

    void cubic_to(Point c1, Point c2, Point p) {
        add({current_, c1, c2, p});
        last_control_ = c2;
        current_ = p;
    }

    void quadratic_to(Point q, Point p) {
        add(quadratic_cubic(current_, q, p));
        last_control_ = q;
        current_ = p;
    }

    Scanner s_;
    const Affine& to_mm_;
    double tolerance_mm_;
    CubicSubpaths out_;
    bool open_ = false;
    Point current_, start_, last_control_;
    char previous_ = 0;
    char written_ = 0;
};

}  // namespace

CubicSubpaths parse_path_data(std::string_view d, const Affine& to_mm, double tolerance_mm) {
    return PathData(d, to_mm, tolerance_mm).parse();
}

}  // namespace pathstream::host::svg
