// Layers and pen changes: Inkscape layers and stroke colours read as layers, choosing layers,
// a pause between layers that the plan carries to the wire, per-layer feeds, and a path order
// that never moves a subpath across a layer or a pause.
#include <catch2/catch.hpp>
#include <string>
#include <vector>

#include "pathstream/device/wire_span.hpp"
#include "pathstream/host/geometry.hpp"
#include "pathstream/host/layers.hpp"
#include "pathstream/host/planner.hpp"
#include "pathstream/host/svg_path.hpp"
#include "pathstream/host/wire_plan.hpp"
#include "pathstream/machine/machine.hpp"

using namespace pathstream;
using namespace pathstream::host;

namespace {

const char* const kLayered = R"(<svg xmlns="http://www.w3.org/2000/svg"
  xmlns:inkscape="http://www.inkscape.org/namespaces/inkscape" width="100mm" height="100mm" viewBox="0 0 100 100">
  <path d="M 1 1 L 5 1" stroke="black"/>
  <g inkscape:groupmode="layer" inkscape:label="black">
    <path d="M 10 10 L 40 10" stroke="black"/>
    <g inkscape:groupmode="layer" inkscape:label="sub"><path d="M 60 60 L 70 70" stroke="blue"/></g>
  </g>
  <g inkscape:groupmode="layer" inkscape:label="hidden" style="display:none"><path d="M 0 0 L 9 9"/></g>
  <g inkscape:groupmode="layer" id="layer7"><path d="M 10 60 L 40 90" stroke="red"/>
    <path d="M 50 90 L 90 90" stroke="red"/></g>
  <g inkscape:groupmode="layer" inkscape:label="black2"><path d="M 80 10 L 90 20"/></g>
</svg>)";

const char* const kColours =
    R"(<svg xmlns="http://www.w3.org/2000/svg" width="100mm" height="100mm" viewBox="0 0 100 100">
  <path d="M 10 10 L 20 10" stroke="#F00"/>
  <path d="M 10 20 L 20 20" stroke="black"/>
  <path d="M 10 30 L 20 30" stroke="#ff0000"/>
</svg>)";

std::vector<std::string> names(const Path& p) {
    std::vector<std::string> out;
    for (const PathLayer& l : p.layers) out.push_back(l.name);
    return out;
}

std::vector<std::size_t> layer_of_each(const Path& p) {
    std::vector<std::size_t> out;
    for (const Subpath& s : p.subpaths) out.push_back(s.layer);
    return out;
}

MachineProfile plotter() {
    return load_machine_profile(std::string(PATHSTREAM_SOURCE_DIR) +
                                "/examples/machines/pen_plotter.json");
}

}  // namespace

TEST_CASE("layers: Inkscape layers by label, id, sublayers in theirs, hidden ones gone",
          "[layers]") {
    const Path p = parse_svg_path(kLayered, "layered.svg");
    CHECK(names(p) == std::vector<std::string>{"(outside layers)", "black", "layer7", "black2"});
    CHECK(layer_of_each(p) == std::vector<std::size_t>{0, 1, 1, 2, 2, 3});
    CHECK(p.layers[1].location.line == 4);
}

TEST_CASE("layers: stroke colours become layers when there are no Inkscape layers", "[layers]") {
    const Path p = parse_svg_path(kColours, "colours.svg");
    CHECK(names(p) == std::vector<std::string>{"#ff0000", "#000000"});
    CHECK(layer_of_each(p) == std::vector<std::size_t>{0, 1, 0});
    const Path one =
        parse_svg_path(R"(<svg xmlns="http://www.w3.org/2000/svg"><path d="M0 0 L1 1" stroke="red"/>
        <path d="M2 2 L3 3" stroke="red"/></svg>)",
                       "one.svg");
    CHECK(one.layers.empty());
}

TEST_CASE("layers: choose by name or number, grouped in layer order, a pause between them",
          "[layers]") {
    const Path p = parse_svg_path(kColours, "colours.svg");
    CHECK(select_layers(p, {"#000000"}).subpaths.size() == 1);
    CHECK(select_layers(p, {"1"}).subpaths.size() == 2);
    CHECK(select_layers(p, {"1", "2"}).subpaths.size() == 3);
    CHECK_THROWS_WITH(
        select_layers(p, {"green"}),
        "--layer green: no such layer (the drawing has 1: \"#ff0000\", 2: \"#000000\")");
    CHECK_THROWS_WITH(select_layers(p, {"3"}), Catch::Contains("--layer 3: no such layer"));
    Path g = group_by_layer(p);
    CHECK(layer_of_each(g) == std::vector<std::size_t>{0, 0, 1});
    CHECK(g.subpaths[1].points.front()[1] == 30);  // stable within the layer
    pause_between_layers(g);
    CHECK_FALSE(g.subpaths[0].pause_before);
    CHECK_FALSE(g.subpaths[1].pause_before);
    CHECK(g.subpaths[2].pause_before);
    CHECK(count_pauses(g) == 1);
}

TEST_CASE("layers: the profile's layer feeds, for subpaths without their own", "[layers]") {
    MachineProfile m = plotter();
    m.layer_feeds = {{"#000000", 12.5}, {"not in this drawing", 3}};
    Path p = parse_svg_path(kColours, "colours.svg");
    p.subpaths[2].feed = 40;
    apply_layer_feeds(p, m);
    CHECK(p.subpaths[0].feed == 0);
    CHECK(p.subpaths[1].feed == 12.5);
    CHECK(p.subpaths[2].feed == 40);
    CHECK(layers_json(p)[1]["feed_mm_s"] == 12.5);
    CHECK(layers_json(p)[0]["feed_mm_s"].is_null());
}

TEST_CASE("layers: a pause where the pen changes, at every layer, or never", "[layers]") {
    const Path p = group_by_layer(parse_svg_path(kLayered, "layered.svg"));
    // Pens: "#000000", "mixed" (black and blue), "#ff0000", "" (no stroke: any pen).
    std::vector<std::string> pens;
    for (const PathLayer& l : p.layers) pens.push_back(l.pen);
    CHECK(pens == std::vector<std::string>{"#000000", "mixed", "#ff0000", ""});
    const auto pauses_at = [&](LayerPause when) {
        Path q = p;
        pause_between_layers(q, when);
        std::vector<std::size_t> at;
        for (std::size_t i = 0; i < q.subpaths.size(); ++i)
            if (q.subpaths[i].pause_before) at.push_back(i);
        return at;
    };
    CHECK(pauses_at(LayerPause::kPenChange) == std::vector<std::size_t>{1, 3});
    CHECK(pauses_at(LayerPause::kEveryLayer) == std::vector<std::size_t>{1, 3, 5});
    CHECK(pauses_at(LayerPause::kNone).empty());
}

TEST_CASE("layers: the path order keeps pauses in place", "[layers][order]") {
    Path p = group_by_layer(parse_svg_path(kLayered, "layered.svg"));
    pause_between_layers(p, LayerPause::kEveryLayer);
    OrderReport r;
    const Path ordered = order_sections(p, {}, &r);
    REQUIRE(ordered.subpaths.size() + r.merged == p.subpaths.size());
    std::size_t pauses = 0;
    for (std::size_t i = 0; i < ordered.subpaths.size(); ++i) {
        const Subpath& s = ordered.subpaths[i];
        if (i > 0) CHECK(s.layer >= ordered.subpaths[i - 1].layer);
        const bool first_of_layer = i > 0 && s.layer != ordered.subpaths[i - 1].layer;
        CHECK(s.pause_before == first_of_layer);
        pauses += s.pause_before ? 1 : 0;
    }
    CHECK(pauses == 3);
    CHECK(r.travel_after <= r.travel_before + 1e-9);
}

TEST_CASE("layers: the plan pauses pen up and at rest, marked on the wire", "[layers][pause]") {
    Path p = group_by_layer(parse_svg_path(kColours, "colours.svg"));
    pause_between_layers(p);
    const Plan plan = plan_path(to_bezier_segments(p), plotter());
    REQUIRE(plan.pauses.size() == 1);
    CHECK(plan.pauses[0].subpath == 2);
    std::uint64_t tick = 0;
    std::size_t marked = 0;
    const WirePlan wire = encode_wire_plan(plan);
    for (std::size_t i = 0; i < plan.spans.size(); ++i) {
        const CoreSpan& s = plan.spans[i];
        tick += s.ticks;
        const bool wire_pause = (wire.spans[i][2] & device::kWirePause) != 0;
        CHECK(wire_pause == s.pause_after);
        if (!s.pause_after) continue;
        ++marked;
        CHECK(tick == plan.pauses[0].tick);
        CHECK_FALSE(s.pen_down);
        for (const auto& c : s.control) CHECK(c[3] == 0);  // ends at rest
        REQUIRE(i + 1 < plan.spans.size());
        CHECK(plan.spans[i + 1].subpath == 2);
    }
    CHECK(marked == 1);
}
