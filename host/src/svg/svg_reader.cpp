// The SVG document walk: XML, elements, attributes and their places, units and transforms.
#include <algorithm>
#include <array>
#include <cmath>
#include <fstream>
#include <limits>
#include <optional>
#include <pugixml.hpp>
#include <sstream>
#include <unordered_map>

#include "pathstream/host/input_error.hpp"
#include "pathstream/host/svg_path.hpp"

namespace pathstream::host {
namespace {

using svg::Affine;
using svg::CubicSubpaths;
using svg::Point;

constexpr double kMaxCoordinateMm = 1e6;  // as the JSON reader: catches unit mix-ups
constexpr double kDegenerateMm = 1e-9;    // pieces smaller than this are dropped
constexpr std::size_t kMaxUses = 100000;  // <use> copies per document: stops exponential nesting
// Elements nested within one another, <use> targets included: far beyond what drawing programs
// write, and well within the stack (the walk recurses once per level).
constexpr std::size_t kMaxDepth = 500;
// Curve pieces a document may expand to: a base plus 16 per byte of the file, so that copies
// (<use>) cannot turn a small file into unbounded geometry (about 200 bytes of memory a piece).
constexpr std::size_t kPiecesBase = 250000;
constexpr std::size_t kPiecesPerByte = 16;
constexpr double kMmPerPx = 25.4 / 96.0;
constexpr double kNoBase = std::numeric_limits<double>::quiet_NaN();
constexpr std::size_t kNoLayer = static_cast<std::size_t>(-1);
constexpr const char* kSvgNamespace = "http://www.w3.org/2000/svg";

bool is_space(char c) {
    return c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == '\f';
}

std::string trim(std::string_view s) {
    while (!s.empty() && is_space(s.front())) s.remove_prefix(1);
    while (!s.empty() && is_space(s.back())) s.remove_suffix(1);
    return std::string(s);
}

std::string lower(std::string s) {
    for (char& c : s) {
        if (c >= 'A' && c <= 'Z') c = static_cast<char>(c - 'A' + 'a');
    }
    return s;
}

std::string number_text(double v, int precision = 6) {
    std::ostringstream o;
    o.precision(precision);
    o << v;
    return o.str();
}

// What the walk carries down the tree.
struct State {
    Affine to_mm;            // user units of this element -> mm
    double width = kNoBase;  // viewport size in user units, for percentages
    double height = kNoBase;
    bool visible = true;  // inherited 'visibility'
    std::string stroke = "none";  // inherited 'stroke', kept for SvgReadInfo::strokes
    std::size_t layer = kNoLayer;  // the Inkscape layer the element is in (index in layers_)
};

// One property's cascaded value: from a presentation attribute, or from CSS (a <style> rule or
// the style attribute) with the byte offset of the declaration, for error places.
struct Cascaded {
    std::string value;
    bool set = false;
    bool css = false;
    std::size_t offset = 0;
};

// The properties the reader uses, after the cascade.
struct Style {
    Cascaded display, visibility, stroke, transform, origin;
};

class Reader {
public:
    Reader(const std::string& text, const std::string& file, double tolerance_mm)
        : text_(text), file_(file), tolerance_mm_(tolerance_mm), locator_(text) {}

    Path read(svg::SvgReadInfo* info) {
        Path path = read();
        if (info) {
            info->strokes = strokes_;
            info->style_rules = sheet_.rules();
            info->location_bytes_scanned = locator_.bytes_scanned();
            info->locations = locator_.lookups();
        }
        return path;
    }

private:
    Path read() {
        const pugi::xml_parse_result result =
            doc_.load_buffer(text_.data(), text_.size(), pugi::parse_default, pugi::encoding_utf8);
        if (!result) {
            std::string what = result.description();
            if (!what.empty() && what[0] >= 'A' && what[0] <= 'Z')
                what[0] = static_cast<char>(what[0] - 'A' + 'a');
            throw InputError(file_, locate(static_cast<std::size_t>(result.offset)),
                             "invalid XML: " + what);
        }
        const pugi::xml_node root = doc_.document_element();
        if (svg_name(root) != "svg") {
            throw InputError(file_, element_location(root),
                             "root element is <" + std::string(root.name()) + ">, expected <svg>");
        }
        style_sheets(root);
        root_svg(root);
        if (path_.subpaths.empty())
            throw InputError(file_, element_location(root), "no drawable paths");
        path_.axes = 2;
        assign_layers();
        return std::move(path_);
    }

    // ---- layers ----------------------------------------------------------------------------

    // Inkscape layers when the drawing has any (drawn content outside them goes to a layer of
    // its own, first); else one layer per stroke colour when there are several; else none.
    void assign_layers() {
        bool outside = false;
        for (std::size_t i = 0; i < path_.subpaths.size(); ++i)
            outside = outside || subpath_layers_[i] == kNoLayer;
        if (!layers_.empty()) {
            const std::size_t shift = outside ? 1 : 0;
            if (outside) path_.layers.push_back({"(outside layers)", {}, 0, ""});
            for (PathLayer& l : layers_) path_.layers.push_back(std::move(l));
            for (std::size_t i = 0; i < path_.subpaths.size(); ++i) {
                path_.subpaths[i].layer = subpath_layers_[i] == kNoLayer ? 0 : subpath_layers_[i] + shift;
                const std::string colour = normal_colour(strokes_[i]);
                std::string& pen = path_.layers[path_.subpaths[i].layer].pen;
                if (colour == "none") continue;
                pen = pen.empty() || pen == colour ? colour : "mixed";
            }
            return;
        }
        std::vector<std::string> colours;
        for (std::size_t i = 0; i < path_.subpaths.size(); ++i) {
            const std::string colour = normal_colour(strokes_[i]);
            const auto at = std::find(colours.begin(), colours.end(), colour);
            path_.subpaths[i].layer = static_cast<std::size_t>(at - colours.begin());
            if (at == colours.end()) {
                colours.push_back(colour);
                path_.layers.push_back({colour, path_.subpaths[i].location, 0, colour == "none" ? "" : colour});
            }
        }
        if (colours.size() < 2) {
            path_.layers.clear();
            for (Subpath& s : path_.subpaths) s.layer = 0;
        }
    }

    // One spelling per colour: lower case, #rgb as #rrggbb, CSS's basic colour names as hex.
    static std::string normal_colour(std::string c) {
        c = lower(trim(c));
        if (c.size() == 4 && c[0] == '#') c = std::string("#") + c[1] + c[1] + c[2] + c[2] + c[3] + c[3];
        static const std::pair<const char*, const char*> kNamed[] = {
            {"black", "#000000"},  {"silver", "#c0c0c0"}, {"gray", "#808080"},   {"grey", "#808080"},
            {"white", "#ffffff"},  {"maroon", "#800000"}, {"red", "#ff0000"},    {"purple", "#800080"},
            {"fuchsia", "#ff00ff"}, {"magenta", "#ff00ff"}, {"green", "#008000"}, {"lime", "#00ff00"},
            {"olive", "#808000"},  {"yellow", "#ffff00"}, {"navy", "#000080"},   {"blue", "#0000ff"},
            {"teal", "#008080"},   {"aqua", "#00ffff"},   {"cyan", "#00ffff"},   {"orange", "#ffa500"}};
        for (const auto& [name, hex] : kNamed)
            if (c == name) return hex;
        return c.empty() ? "none" : c;
    }

    // A top-level Inkscape layer (<g inkscape:groupmode="layer">; sublayers belong to theirs):
    // named by its label, else its id, else its number.
    void enter_layer(pugi::xml_node n, State& state) {
        if (state.layer != kNoLayer || std::string(n.attribute("inkscape:groupmode").value()) != "layer") return;
        std::string name = trim(n.attribute("inkscape:label").value());
        if (name.empty()) name = trim(n.attribute("id").value());
        if (name.empty()) name = std::to_string(layers_.size() + 1);
        state.layer = layers_.size();
        layers_.push_back({name, element_location(n), 0, ""});
    }

    // ---- places ----------------------------------------------------------------------------

    // Line and column (1-based, columns in characters of UTF-8) of a byte offset.
    SourceLocation locate(std::size_t offset) const { return locator_.locate(offset); }

    // Byte offset of an element's '<' (pugixml gives the offset of its name).
    std::size_t element_offset(pugi::xml_node n) const {
        const std::ptrdiff_t name = n.offset_debug();
        return name > 0 ? static_cast<std::size_t>(name - 1) : 0;
    }

    SourceLocation element_location(pugi::xml_node n) const { return locate(element_offset(n)); }

    // Where an attribute's name starts in the element's start tag; the element if not found.
    SourceLocation attribute_location(pugi::xml_node n, const char* name) const {
        return locate(attribute_offsets(n, name).first);
    }

    // Byte offsets of an attribute's name and of its value's first character in the start
    // tag; the element's '<' for both if not found.
    std::pair<std::size_t, std::size_t> attribute_offsets(pugi::xml_node n,
                                                          const char* name) const {
        const std::string_view t = text_;
        const std::size_t start = element_offset(n);
        std::size_t i = start + 1;
        const auto stop = [&](char c) { return is_space(c) || c == '>' || c == '/' || c == '='; };
        while (i < t.size() && !stop(t[i])) ++i;  // the element's name
        for (;;) {
            while (i < t.size() && is_space(t[i])) ++i;
            if (i >= t.size() || t[i] == '>' || t[i] == '/') break;
            const std::size_t name_at = i;
            std::size_t value_at = i;
            while (i < t.size() && !stop(t[i])) ++i;
            const std::string_view attribute = t.substr(name_at, i - name_at);
            while (i < t.size() && is_space(t[i])) ++i;
            if (i < t.size() && t[i] == '=') {
                ++i;
                while (i < t.size() && is_space(t[i])) ++i;
                if (i < t.size() && (t[i] == '"' || t[i] == '\'')) {
                    const char quote = t[i++];
                    value_at = i;
                    while (i < t.size() && t[i] != quote) ++i;
                    ++i;
                }
            }
            if (attribute == name) return {name_at, value_at};
            if (i == name_at) break;  // cannot happen in a document pugixml accepted
        }
        return {start, start};
    }

    [[noreturn]] void fail_at(pugi::xml_node n, const char* attribute,
                              const std::string& message) const {
        throw InputError(file_, attribute ? attribute_location(n, attribute) : element_location(n),
                         message);
    }

    // Runs parse(value of attribute) and gives its ValueError the attribute's place.
    template <class F>
    auto with_attribute(pugi::xml_node n, const char* attribute, F&& parse) const {
        try {
            return parse(std::string_view(n.attribute(attribute).value()));
        } catch (const svg::ValueError& e) {
            fail_at(n, attribute, e.what());
        }
    }

    // ---- names, styles -----------------------------------------------------------------------

    // The local name of an element in the SVG namespace ("" for others, e.g. sodipodi:namedview).
    // Unprefixed names count as SVG; a prefix counts when some ancestor binds it to SVG.
    static std::string svg_name(pugi::xml_node n) {
        const std::string name = n.name();
        const auto colon = name.find(':');
        if (colon == std::string::npos) return name;
        const std::string binding = "xmlns:" + name.substr(0, colon);
        for (pugi::xml_node a = n; a; a = a.parent()) {
            if (const pugi::xml_attribute ns = a.attribute(binding.c_str())) {
                return std::string(ns.value()) == kSvgNamespace ? name.substr(colon + 1) : "";
            }
        }
        return "";
    }

    // Reads every <style> element (SVG namespace, type text/css or none), wherever it is:
    // CSS applies to the whole document.
    void style_sheets(pugi::xml_node root) {
        std::vector<pugi::xml_node> todo{root};
        while (!todo.empty()) {
            const pugi::xml_node e = todo.back();
            todo.pop_back();
            if (svg_name(e) == "style") {
                const std::string type = lower(trim(e.attribute("type").value()));
                if (!type.empty() && type != "text/css") continue;
                for (pugi::xml_node c = e.first_child(); c; c = c.next_sibling()) {
                    if (c.type() != pugi::node_pcdata && c.type() != pugi::node_cdata) continue;
                    const std::ptrdiff_t at = c.offset_debug();
                    try {
                        sheet_.add(c.value(), at > 0 ? static_cast<std::size_t>(at) : 0);
                    } catch (const svg::CssError& error) {
                        throw InputError(file_, locate(error.offset), error.what());
                    }
                }
                continue;
            }
            for (pugi::xml_node c = e.last_child(); c; c = c.previous_sibling()) {
                if (c.type() == pugi::node_element) todo.push_back(c);
            }
        }
    }

    // The cascade for the properties the reader uses: presentation attribute < <style> rules
    // (by specificity, then order) < style attribute, and !important declarations above all
    // normal ones. Keywords are lower-cased; transform values keep their case.
    Style style(pugi::xml_node n) const {
        Style st;
        const auto attribute = [&](Cascaded& slot, const char* name) {
            if (const pugi::xml_attribute a = n.attribute(name)) {
                std::string v = trim(a.value());
                if (const auto bang = v.find("!important"); bang != std::string::npos)
                    v = trim(v.substr(0, bang));
                slot = {v, true, false, 0};
            }
        };
        attribute(st.display, "display");
        attribute(st.visibility, "visibility");
        attribute(st.stroke, "stroke");
        attribute(st.transform, "transform");
        attribute(st.origin, "transform-origin");
        std::vector<const svg::CssDeclaration*> sheet;
        if (!sheet_.empty()) {
            sheet = sheet_.match(svg_name(n), n.attribute("id").value(),
                                 n.attribute("class").value());
        }
        std::vector<svg::CssDeclaration> inline_style;
        if (const pugi::xml_attribute a = n.attribute("style")) {
            try {
                inline_style = svg::parse_css_declarations(a.value(),
                                                           attribute_offsets(n, "style").second);
            } catch (const svg::CssError& error) {
                throw InputError(file_, locate(error.offset), error.what());
            }
        }
        const auto apply = [&](const svg::CssDeclaration& d) {
            Cascaded* slot = d.name == "display"            ? &st.display
                             : d.name == "visibility"       ? &st.visibility
                             : d.name == "stroke"           ? &st.stroke
                             : d.name == "transform"        ? &st.transform
                             : d.name == "transform-origin" ? &st.origin
                                                            : nullptr;
            if (slot) *slot = {d.value, true, true, d.name_offset};
        };
        for (const bool important : {false, true}) {
            for (const svg::CssDeclaration* d : sheet) {
                if (d->important == important) apply(*d);
            }
            for (const svg::CssDeclaration& d : inline_style) {
                if (d.important == important) apply(d);
            }
        }
        for (Cascaded* keyword : {&st.display, &st.visibility, &st.stroke})
            keyword->value = lower(keyword->value);
        return st;
    }

    // Applies a computed visibility and stroke to the inherited state.
    static void inherit(const Style& st, State& state) {
        if (st.visibility.value == "hidden" || st.visibility.value == "collapse")
            state.visible = false;
        if (st.visibility.value == "visible") state.visible = true;
        if (st.stroke.set && st.stroke.value != "inherit" && !st.stroke.value.empty())
            state.stroke = st.stroke.value;
    }

    // ---- values -----------------------------------------------------------------------------

    // The element's transform (CSS property, else attribute) about its transform-origin, whose
    // percentages and keywords refer to the viewport `width` x `height` in user units.
    Affine transform(pugi::xml_node n, const Style& st, double width, double height) const {
        if (!st.transform.set) return {};
        const auto parse = [&](const Cascaded& c, const char* attribute, auto&& f) {
            if (!c.css) return with_attribute(n, attribute, [&](std::string_view) { return f(c.value); });
            try {
                return f(c.value);
            } catch (const svg::ValueError& e) {
                throw InputError(file_, locate(c.offset), e.what());
            }
        };
        const Affine m = parse(st.transform, "transform", [&](std::string_view v) {
            return svg::parse_transform(v, st.transform.css);
        });
        if (!st.origin.set) return m;
        const Point o = parse(st.origin, "transform-origin", [&](std::string_view v) {
            return svg::parse_transform_origin(v, width, height);
        });
        return Affine::translate(o.x, o.y) * m * Affine::translate(-o.x, -o.y);
    }

    // A length attribute in user units; `fallback` when absent.
    double length(pugi::xml_node n, const char* attribute, double percent_base,
                  double fallback) const {
        if (!n.attribute(attribute)) return fallback;
        return with_attribute(n, attribute, [&](std::string_view v) {
            return svg::parse_length(v, attribute, percent_base);
        });
    }

    // A size (width, r, ...) that must not be negative.
    double size(pugi::xml_node n, const char* attribute, double percent_base,
                double fallback) const {
        const double v = length(n, attribute, percent_base, fallback);
        if (v < 0) {
            fail_at(n, attribute,
                    "<" + svg_name(n) + "> " + attribute + " must not be negative (got " +
                        trim(n.attribute(attribute).value()) + ")");
        }
        return v;
    }

    // rx / ry of rect and ellipse: NaN for "auto" or absent.
    double radius(pugi::xml_node n, const char* attribute, double percent_base) const {
        if (trim(n.attribute(attribute).value()) == "auto") return kNoBase;
        return size(n, attribute, percent_base, kNoBase);
    }

    std::optional<std::array<double, 4>> view_box(pugi::xml_node n) const {
        if (!n.attribute("viewBox")) return std::nullopt;
        return with_attribute(n, "viewBox", [](std::string_view v) {
            const std::vector<double> numbers = svg::parse_number_list(v, "viewBox");
            if (numbers.size() != 4) {
                throw svg::ValueError(
                    "viewBox: expected 4 numbers (min-x min-y width height), got " +
                    std::to_string(numbers.size()));
            }
            if (!(numbers[2] > 0) || !(numbers[3] > 0)) {
                throw svg::ValueError("viewBox: width and height must be positive (got " +
                                      number_text(numbers[2]) + " x " + number_text(numbers[3]) +
                                      ")");
            }
            return std::array<double, 4>{numbers[0], numbers[1], numbers[2], numbers[3]};
        });
    }

    Affine viewbox_map(pugi::xml_node n, const std::array<double, 4>& box, double width,
                       double height) const {
        return with_attribute(n, "preserveAspectRatio", [&](std::string_view v) {
            return svg::viewbox_transform(box, width, height, v);
        });
    }

    // ---- the walk ---------------------------------------------------------------------------

    void root_svg(pugi::xml_node n) {
        State state;
        const Style st = style(n);
        inherit(st, state);
        if (st.display.value == "none") return;
        // Width and height in px; percentages mean "no size given" for the outermost <svg>.
        const auto given = [&](const char* attribute) {
            const std::string v = trim(n.attribute(attribute).value());
            return !v.empty() && v.back() != '%';
        };
        double width = given("width") ? size(n, "width", kNoBase, 0) : kNoBase;
        double height = given("height") ? size(n, "height", kNoBase, 0) : kNoBase;
        Affine view;
        if (const auto box = view_box(n)) {
            const double w = (*box)[2], h = (*box)[3];
            if (std::isnan(width) && std::isnan(height)) {
                width = w;  // no size: one user unit is one px
                height = h;
            } else if (std::isnan(width)) {
                width = height * w / h;
            } else if (std::isnan(height)) {
                height = width * h / w;
            }
            view = viewbox_map(n, *box, width, height);
            state.width = w;
            state.height = h;
        } else {
            state.width = width;
            state.height = height;
        }
        if (width == 0 || height == 0) return;  // a zero-sized drawing draws nothing
        state.to_mm = Affine::scale(kMmPerPx, kMmPerPx) * transform(n, st, width, height) * view;
        if (state.to_mm.determinant() == 0) return;
        children(n, state);
    }

    void children(pugi::xml_node n, const State& state) {
        for (pugi::xml_node child = n.first_child(); child; child = child.next_sibling()) {
            if (child.type() == pugi::node_element) element(child, state);
        }
    }

    static bool conditions_hold(pugi::xml_node n) {
        // <switch>: we know no extensions or languages, so any such test fails.
        return !n.attribute("requiredExtensions") && !n.attribute("systemLanguage");
    }

    // Counts one level of nesting for the walk below it.
    struct DepthGuard {
        std::size_t& depth;
        ~DepthGuard() { --depth; }
    };

    void element(pugi::xml_node n, const State& parent) {
        if (depth_ >= kMaxDepth) {
            fail_at(n, nullptr, "elements nested more than " + std::to_string(kMaxDepth) +
                                    " deep (the reader's limit)");
        }
        ++depth_;
        const DepthGuard guard{depth_};
        const std::string name = svg_name(n);
        if (name.empty()) return;
        const Style st = style(n);
        if (st.display.value == "none") return;
        State state = parent;
        inherit(st, state);
        static const char* const kDrawn[] = {"g",    "a",    "switch",  "svg",  "use",
                                             "path", "rect", "circle",  "ellipse",
                                             "line", "polyline", "polygon"};
        if (std::find(std::begin(kDrawn), std::end(kDrawn), name) == std::end(kDrawn))
            return;  // defs, symbol, text, image, metadata, title, style, ...
        const Affine own = transform(n, st, parent.width, parent.height);

        if (name == "g") enter_layer(n, state);
        if (name == "g" || name == "a" || name == "switch") {
            state.to_mm = parent.to_mm * own;
            if (state.to_mm.determinant() == 0) return;
            if (name != "switch") return children(n, state);
            for (pugi::xml_node child = n.first_child(); child; child = child.next_sibling()) {
                if (child.type() == pugi::node_element && !svg_name(child).empty() &&
                    conditions_hold(child)) {
                    return element(child, state);
                }
            }
            return;
        }
        if (name == "svg") return nested_svg(n, parent, own, state);
        if (name == "use") return use(n, parent, own, state);
        state.to_mm = parent.to_mm * own;
        if (state.to_mm.determinant() == 0 || !state.visible) return;
        geometry(n, name, state);
    }

    void nested_svg(pugi::xml_node n, const State& parent, const Affine& own, State state) {
        const double x = length(n, "x", parent.width, 0), y = length(n, "y", parent.height, 0);
        const double width = size(n, "width", parent.width, parent.width);
        const double height = size(n, "height", parent.height, parent.height);
        viewport(n, parent.to_mm * own * Affine::translate(x, y), width, height, state);
    }

    // Enters the viewport of a nested <svg> or of a <symbol> drawn by <use>: `n`'s viewBox and
    // preserveAspectRatio map its user units onto width x height at the origin of `to_mm`.
    void viewport(pugi::xml_node n, const Affine& to_mm, double width, double height, State state) {
        if (width == 0 || height == 0) return;  // a zero-sized viewport draws nothing
        state.width = width;
        state.height = height;
        state.to_mm = to_mm;
        if (const auto box = view_box(n)) {
            if (std::isnan(width) || std::isnan(height)) {
                fail_at(n, "viewBox",
                        "a viewBox needs a viewport size (give <" + svg_name(n) +
                            "> a width and height, or the root <svg> a size)");
            }
            state.to_mm = to_mm * viewbox_map(n, *box, width, height);
            state.width = (*box)[2];
            state.height = (*box)[3];
        }
        if (state.to_mm.determinant() == 0) return;
        children(n, state);
    }

    // <use href="#id">: the element with that id, drawn here, moved by x and y. A <symbol>
    // gets a viewport of the use's width and height. Other files' content is not drawn.
    void use(pugi::xml_node n, const State& parent, const Affine& own, State state) {
        const char* const href_name = n.attribute("href") ? "href" : "xlink:href";
        const std::string href = trim(n.attribute(href_name).value());
        if (href.size() < 2 || href[0] != '#') return;
        // Every copy counts, of nothing too: a reference to nothing costs a lookup.
        if (++use_count_ > kMaxUses) {
            fail_at(n, nullptr,
                    "too many <use> copies (more than " + std::to_string(kMaxUses) + ")");
        }
        const pugi::xml_node target = element_by_id(href.substr(1));
        if (!target) return;  // SVG: a reference to nothing draws nothing
        for (const pugi::xml_node& active : use_stack_) {
            if (active == target) {
                fail_at(
                    n, href_name,
                    "<use> refers to " + href + ", which contains this <use> (circular reference)");
            }
        }
        const double x = length(n, "x", parent.width, 0), y = length(n, "y", parent.height, 0);
        const Affine to_mm = parent.to_mm * own * Affine::translate(x, y);
        if (to_mm.determinant() == 0) return;
        use_stack_.push_back(target);
        if (svg_name(target) == "symbol") {
            const Style target_style = style(target);
            if (target_style.display.value != "none") {
                inherit(target_style, state);
                const auto side = [&](const char* attribute, double base) {
                    if (n.attribute(attribute)) return size(n, attribute, base, base);
                    return size(target, attribute, base, base);
                };
                viewport(target,
                         to_mm * transform(target, target_style, parent.width, parent.height),
                         side("width", parent.width),
                         side("height", parent.height), state);
            }
        } else {
            state.to_mm = to_mm;
            element(target, state);
        }
        use_stack_.pop_back();
    }

    pugi::xml_node element_by_id(const std::string& id) {
        if (!ids_built_) {
            ids_built_ = true;
            std::vector<pugi::xml_node> todo{doc_.document_element()};
            while (!todo.empty()) {
                const pugi::xml_node e = todo.back();
                todo.pop_back();
                if (const pugi::xml_attribute a = e.attribute("id"))
                    ids_.emplace(a.value(), e);  // first one wins
                for (pugi::xml_node c = e.last_child(); c; c = c.previous_sibling()) {
                    if (c.type() == pugi::node_element) todo.push_back(c);
                }
            }
        }
        const auto it = ids_.find(id);
        return it == ids_.end() ? pugi::xml_node() : it->second;
    }

    void geometry(pugi::xml_node n, const std::string& name, const State& state) {
        const double w = state.width, h = state.height;
        const double diagonal = std::sqrt((w * w + h * h) / 2);  // what 100% of r is
        const Affine& m = state.to_mm;
        if (name == "path") {
            if (!n.attribute("d")) return;
            const CubicSubpaths pieces = with_attribute(n, "d", [&](std::string_view d) {
                return svg::parse_path_data(d, m, tolerance_mm_);
            });
            return emit(pieces, state, attribute_location(n, "d"));
        }
        if (name == "polyline" || name == "polygon") {
            const std::vector<Point> points = with_attribute(n, "points", [](std::string_view v) {
                const std::vector<double> numbers = svg::parse_number_list(v, "points");
                if (numbers.size() % 2 != 0) {
                    throw svg::ValueError("points: odd number of coordinates (" +
                                          std::to_string(numbers.size()) + ")");
                }
                std::vector<Point> out;
                for (std::size_t i = 0; i < numbers.size(); i += 2)
                    out.push_back({numbers[i], numbers[i + 1]});
                return out;
            });
            return emit(CubicSubpaths{svg::polyline_cubics(points, name == "polygon")}, state,
                        attribute_location(n, "points"));
        }
        const SourceLocation at = element_location(n);
        if (name == "line") {
            const Point a{length(n, "x1", w, 0), length(n, "y1", h, 0)};
            const Point b{length(n, "x2", w, 0), length(n, "y2", h, 0)};
            return emit(CubicSubpaths{std::vector<svg::Cubic>{svg::line_cubic(a, b)}}, state, at);
        }
        if (name == "rect") {
            const double x = length(n, "x", w, 0), y = length(n, "y", h, 0);
            const double width = size(n, "width", w, 0), height = size(n, "height", h, 0);
            double rx = radius(n, "rx", w), ry = radius(n, "ry", h);
            if (width == 0 || height == 0) return;
            if (std::isnan(rx) && std::isnan(ry))
                rx = ry = 0;
            else if (std::isnan(rx))
                rx = ry;
            else if (std::isnan(ry))
                ry = rx;
            rx = std::min(rx, width / 2);
            ry = std::min(ry, height / 2);
            return emit(
                CubicSubpaths{svg::rect_cubics(x, y, width, height, rx, ry, m, tolerance_mm_)},
                state, at);
        }
        const Point center{length(n, "cx", w, 0), length(n, "cy", h, 0)};
        double rx = 0, ry = 0;
        if (name == "circle") {
            rx = ry = size(n, "r", diagonal, 0);
        } else {  // ellipse
            rx = radius(n, "rx", w);
            ry = radius(n, "ry", h);
            if (std::isnan(rx)) rx = std::isnan(ry) ? 0 : ry;
            if (std::isnan(ry)) ry = rx;
        }
        if (rx == 0 || ry == 0) return;
        emit(CubicSubpaths{svg::ellipse_cubics(center, rx, ry, m, tolerance_mm_)}, state, at);
    }

    // Maps pieces to mm and appends them as Bezier subpaths.
    void emit(const CubicSubpaths& subpaths, const State& state, SourceLocation at) {
        const Affine& to_mm = state.to_mm;
        const std::size_t budget = kPiecesBase + kPiecesPerByte * text_.size();
        for (const auto& pieces : subpaths) {
            pieces_ += pieces.size();
            if (pieces_ > budget) {
                throw InputError(file_, at,
                                 "the drawing expands to more than " + std::to_string(budget) +
                                     " curve pieces (the reader's limit for a file of " +
                                     std::to_string(text_.size()) + " bytes; <use> copies count)");
            }
            // Only straight pieces (lines, polylines, rectangles without corners): a polyline
            // of their ends, 1 point a piece instead of 3; the planner makes the same straight
            // cubics of it (docs/formats-svg.md).
            const bool straight =
                std::all_of(pieces.begin(), pieces.end(),
                            [](const svg::Cubic& c) { return c == svg::line_cubic(c[0], c[3]); });
            Subpath sp;
            sp.basis = straight ? PathBasis::kPolyline : PathBasis::kBezier;
            sp.closed = false;
            sp.location = at;
            // At most this many points: no growth by doubling.
            sp.points.reserve((straight ? 1 : 3) * pieces.size() + 1, 2);
            for (const svg::Cubic& c : pieces) {
                Point mm[4];
                bool degenerate = true;
                for (int k = 0; k < 4; ++k) {
                    mm[k] = to_mm(c[k]);
                    degenerate = degenerate &&
                                 std::hypot(mm[k].x - mm[0].x, mm[k].y - mm[0].y) <= kDegenerateMm;
                }
                if (degenerate) continue;
                for (int k = sp.points.empty() ? 0 : 1; k < 4; ++k) {
                    if (straight && (k == 1 || k == 2)) continue;  // a polyline keeps the ends
                    check(mm[k].x, at);
                    check(mm[k].y, at);
                    sp.points.push_back({mm[k].x, mm[k].y});
                }
            }
            if (sp.points.empty()) continue;
            path_.subpaths.push_back(std::move(sp));
            strokes_.push_back(state.stroke);
            subpath_layers_.push_back(state.layer);
        }
    }

    void check(double mm, SourceLocation at) const {
        if (!std::isfinite(mm))
            throw InputError(file_, at, "coordinate is not finite after units and transforms");
        if (std::fabs(mm) > kMaxCoordinateMm) {
            throw InputError(file_, at,
                             "coordinate " + number_text(mm, 10) +
                                 " mm is out of range (|value| <= " +
                                 number_text(kMaxCoordinateMm) + " mm after units and transforms)");
        }
    }

    const std::string& text_;
    const std::string& file_;
    double tolerance_mm_;
    mutable svg::TextLocator locator_;  // lookups only count their cost
    pugi::xml_document doc_;
    Path path_;
    std::unordered_map<std::string, pugi::xml_node> ids_;
    bool ids_built_ = false;
    std::vector<pugi::xml_node> use_stack_;  // targets of the <use> elements being drawn
    std::size_t use_count_ = 0;
    std::size_t depth_ = 0;   // elements being walked, nested
    std::size_t pieces_ = 0;  // curve pieces emitted so far
    svg::StyleSheet sheet_;
    std::vector<std::string> strokes_;  // parallel to path_.subpaths
    std::vector<std::size_t> subpath_layers_;  // parallel to path_.subpaths: index in layers_
    std::vector<PathLayer> layers_;            // Inkscape layers in document order
};

}  // namespace

Path parse_svg_path(const std::string& text, const std::string& file, double tolerance_mm,
                    svg::SvgReadInfo* info) {
    if (!(tolerance_mm > 0) || !std::isfinite(tolerance_mm)) {
        throw InputError(
            file, {},
            "tolerance must be positive and finite (got " + number_text(tolerance_mm) + " mm)");
    }
    return Reader(text, file, tolerance_mm).read(info);
}

Path load_svg_path(const std::string& file, double tolerance_mm) {
    std::ifstream in(file, std::ios::binary);
    if (!in) throw InputError(file, {}, "cannot open file");
    std::ostringstream buffer;
    buffer << in.rdbuf();
    if (in.bad()) throw InputError(file, {}, "cannot read file");
    return parse_svg_path(buffer.str(), file, tolerance_mm);
}

}  // namespace pathstream::host
