// CSS in SVG: <style> rules by type, class and id, the cascade against presentation and style
// attributes, display, visibility, stroke, the CSS transform and transform-origin.
#include <catch2/catch.hpp>
#include <cmath>
#include <string>

#include "pathstream/host/svg_path.hpp"
#include "pathstream/machine/input_error.hpp"

using namespace pathstream::host;

namespace {

// A document whose user unit is one millimetre: 100 x 100 mm, viewBox 0 0 100 100.
std::string doc(const std::string& body) {
    return R"(<svg xmlns="http://www.w3.org/2000/svg" width="100mm" height="100mm" viewBox="0 0 100 100">)" +
           body + "</svg>";
}

Path parse(const std::string& body, svg::SvgReadInfo* info = nullptr) {
    return parse_svg_path(doc(body), "t.svg", 0.01, info);
}

std::string error_of(const std::string& body) {
    try {
        parse(body);
    } catch (const InputError& e) {
        return e.what();
    }
    return "no error";
}

// Number of subpaths drawn; 0 when the reader finds nothing to draw.
std::size_t drawn(const std::string& body) {
    try {
        return parse(body).subpaths.size();
    } catch (const InputError&) {
        return 0;
    }
}

// First point of the only subpath.
std::pair<double, double> start_of(const std::string& body) {
    const Path p = parse(body);
    REQUIRE(p.subpaths.size() == 1);
    return {p.subpaths[0].points[0][0], p.subpaths[0].points[0][1]};
}

const std::string kLine = R"(<line x1="10" y1="10" x2="20" y2="10")";

}  // namespace

TEST_CASE("svg css: Illustrator's hidden layer class", "[svg]") {
    const std::string body = R"(<style type="text/css">
	.st0{fill:none;stroke:#000000;stroke-miterlimit:10;}
	.st2{display:none;}
</style>
<g id="Layer_1"><line class="st0" x1="0" y1="0" x2="5" y2="5"/></g>
<g id="Layer_2" class="st2"><line class="st0" x1="0" y1="0" x2="9" y2="9"/></g>)";
    svg::SvgReadInfo info;
    const Path p = parse(body, &info);
    REQUIRE(p.subpaths.size() == 1);
    CHECK(p.subpaths[0].points.back()[0] == Approx(5));
    CHECK(info.style_rules == 2);
    REQUIRE(info.strokes.size() == 1);
    CHECK(info.strokes[0] == "#000000");
}

TEST_CASE("svg css: selectors by type, class, id, lists and CDATA", "[svg]") {
    CHECK(drawn("<style>line{display:none}</style>" + kLine + "/>") == 0);
    CHECK(drawn("<style>#a{display:none}</style>" + kLine + " id=\"a\"/>") == 0);
    CHECK(drawn("<style>#a{display:none}</style>" + kLine + " id=\"b\"/>") == 1);
    CHECK(drawn("<style>.x.y{display:none}</style>" + kLine + " class=\"y  x\"/>") == 0);
    CHECK(drawn("<style>.x.y{display:none}</style>" + kLine + " class=\"x\"/>") == 1);
    CHECK(drawn("<style>path.x{display:none}</style>" + kLine + " class=\"x\"/>") == 1);
    CHECK(drawn("<style>*{display:none}</style>" + kLine + "/>") == 0);
    CHECK(drawn("<style>.q, line {display:none}</style>" + kLine + "/>") == 0);
    CHECK(drawn("<style><![CDATA[ .a > .b, .c{display: none} ]]></style>" + kLine +
                " class=\"c\"/>") == 0);
    // A style sheet after the content still applies; <style> in <defs> too.
    CHECK(drawn(kLine + " class=\"h\"/><defs><style>.h{display:none}</style></defs>") == 0);
    // Another style sheet language is not read.
    CHECK(drawn("<style type=\"text/sass\">line{display:none}</style>" + kLine + "/>") == 1);
}

TEST_CASE("svg css: unsupported selectors and at-rules are ignored", "[svg]") {
    const std::string sheet = R"(<style>
  @import url(x.css);
  @media print { line { display: none } }
  @font-face { font-family: a; src: url("a{b}.woff") }
  g line, line:hover, line[id], svg|line, .a\:b, line::before { display: none }
  /* a comment { display: none } */
  <!-- --> line { fill: red; unknown-thing: 1; display }
</style>)";
    CHECK(drawn(sheet + kLine + "/>") == 1);
}

TEST_CASE("svg css: the cascade: attribute < sheet < style attribute", "[svg]") {
    // Specificity: id > class > type, whatever the order.
    CHECK(drawn("<style>#a{display:inline} .c{display:none}</style>" + kLine +
                " id=\"a\" class=\"c\"/>") == 1);
    CHECK(drawn("<style>.c{display:none} line{display:inline}</style>" + kLine +
                " class=\"c\"/>") == 0);
    // Equal specificity: the later rule wins.
    CHECK(drawn("<style>.c{display:none} .d{display:inline}</style>" + kLine +
                " class=\"c d\"/>") == 1);
    CHECK(drawn("<style>.d{display:inline} .c{display:none}</style>" + kLine +
                " class=\"c d\"/>") == 0);
    // A rule beats the presentation attribute; the style attribute beats a rule.
    CHECK(drawn("<style>.c{display:none}</style>" + kLine + " class=\"c\" display=\"inline\"/>") ==
          0);
    CHECK(drawn("<style>.c{display:none}</style>" + kLine +
                " class=\"c\" style=\"display:inline\"/>") == 1);
    // !important in a rule beats the style attribute.
    CHECK(drawn("<style>.c{display:none !important}</style>" + kLine +
                " class=\"c\" style=\"display:inline\"/>") == 0);
    CHECK(drawn(kLine + R"( style="display:none"/>)") == 0);
}

TEST_CASE("svg css: visibility inherits and a child may show again", "[svg]") {
    const std::string sheet = "<style>.h{visibility:hidden} .v{visibility:visible}</style>";
    CHECK(drawn(sheet + "<g class=\"h\">" + kLine + "/></g>") == 0);
    CHECK(drawn(sheet + "<g class=\"h\">" + kLine + " class=\"v\"/></g>") == 1);
    CHECK(drawn("<g style=\"visibility:collapse\">" + kLine + "/></g>") == 0);
}

TEST_CASE("svg css: stroke is kept per subpath, inherited", "[svg]") {
    svg::SvgReadInfo info;
    parse("<style>.r{stroke:#FF0000} g{stroke:blue}</style><g>" + kLine + "/>" + kLine +
              " class=\"r\"/>" + kLine + " stroke=\"none\"/></g>" + kLine + "/>",
          &info);
    REQUIRE(info.strokes.size() == 4);
    CHECK(info.strokes[0] == "blue");
    CHECK(info.strokes[1] == "#ff0000");
    CHECK(info.strokes[2] == "none");  // still drawn: pathstream draws outlines
    CHECK(info.strokes[3] == "none");
}

TEST_CASE("svg css: the CSS transform property", "[svg]") {
    CHECK(start_of("<style>line{transform:translate(5px, 7px)}</style>" + kLine + "/>") ==
          std::pair{15.0, 17.0});
    // The property replaces the attribute.
    CHECK(
        start_of(kLine + R"~( transform="translate(50)" style="transform: translateX(1px)"/>)~") ==
        std::pair{11.0, 10.0});
    const auto [x, y] = start_of(kLine + R"~( style="transform: rotate(0.25turn)"/>)~");
    CHECK(x == Approx(-10));
    CHECK(y == Approx(10));
    CHECK(start_of(kLine + R"~( transform="translate(1)" style="transform:none"/>)~") ==
          std::pair{10.0, 10.0});
    CHECK(error_of("<style>\n.a { transform: spin(3) }</style>" + kLine + " class=\"a\"/>") ==
          "t.svg:2:6: transform: unknown transform 'spin' (expected matrix, translate, scale, "
          "rotate, skewX or skewY) at character 1");
    CHECK(error_of(kLine + R"~( style="transform: rotate(3px)"/>)~") ==
          "t.svg:1:137: transform: unit 'px' not allowed in 'rotate(' at character 9");
}

TEST_CASE("svg: transform-origin as attribute and property", "[svg]") {
    // Rotating 90 degrees about (15, 10) maps (10, 10) to (15, 5).
    for (const std::string origin : {"15 10", "15px 10", "15% 10%", "15 10 0", "15px 10 7mm"}) {
        INFO(origin);
        const auto [x, y] =
            start_of(kLine + " transform=\"rotate(90)\" transform-origin=\"" + origin + "\"/>");
        CHECK(x == Approx(15));
        CHECK(y == Approx(5));
    }
    // Keywords, either order; one value centres the other axis.
    const auto at = [&](const std::string& origin) {
        return start_of(kLine + " transform=\"scale(2)\" transform-origin=\"" + origin + "\"/>");
    };
    CHECK(at("left top") == std::pair{20.0, 20.0});
    CHECK(at("top left") == std::pair{20.0, 20.0});
    CHECK(at("right bottom") == std::pair{-80.0, -80.0});
    CHECK(at("center") == std::pair{-30.0, -30.0});
    CHECK(at("bottom") == std::pair{-30.0, -80.0});
    CHECK(at("10mm 0 0") == std::pair{20.0 - 10.0 * 96 / 25.4, 20.0});
    // As a CSS property, also about a group.
    CHECK(start_of(R"~(<style>g{transform:scale(2);transform-origin:10px 10px}</style><g>)~" +
                   kLine + "/></g>") == std::pair{10.0, 10.0});
    // No transform: the origin changes nothing.
    CHECK(start_of(kLine + " transform-origin=\"50 50\"/>") == std::pair{10.0, 10.0});
    CHECK(
        error_of(kLine + " transform=\"scale(2)\" transform-origin=\"left right\"/>") ==
        "t.svg:1:151: transform-origin: 'left right' puts both values on one axis at character 1");
    CHECK(error_of(kLine + " transform=\"scale(2)\" transform-origin=\"1 2 3 4\"/>") ==
          "t.svg:1:151: transform-origin: expected at most 3 values (x y z) at character 7");
    CHECK(error_of(kLine + " transform=\"scale(2)\" transform-origin=\"1 2em\"/>") ==
          "t.svg:1:151: transform-origin y: unknown unit 'em' (expected mm, cm, in, pt, pc, px, % "
          "or none) at character 4");
}

TEST_CASE("svg css: malformed sheets name the place", "[svg]") {
    CHECK(error_of("<style>\n.a{display:none</style>" + kLine + "/>") ==
          "t.svg:2:3: style: unclosed '{' (no matching '}')");
    CHECK(error_of("<style>\n .a{} /* x</style>" + kLine + "/>") ==
          "t.svg:2:7: style: unclosed comment '/*'");
    CHECK(error_of("<style>\n .a{} }</style>" + kLine + "/>") ==
          "t.svg:2:7: style: unexpected '}'");
    CHECK(error_of("<style>\n  .a</style>" + kLine + "/>") ==
          "t.svg:2:3: style: expected '{' after the selector '.a'");
    // A declaration without a colon or value is dropped (CSS error recovery).
    CHECK(drawn("<style>line{display;;: none; display: }</style>" + kLine + "/>") == 1);
}

TEST_CASE("svg css: more than 10000 rules are refused", "[svg]") {
    std::string sheet = "<style>";
    for (int i = 0; i < 5000; ++i) sheet += ".a" + std::to_string(i) + ",.b{display:inline}";
    CHECK(drawn(sheet + "</style>" + kLine + " class=\"b\"/>") == 1);
    sheet += ".z{display:none}</style>";
    CHECK(error_of(sheet + kLine + "/>")
              .find("style: more than 10000 rules (each selector of a list counts)") !=
          std::string::npos);
}
