// Nothing dropped in silence: what the SVG reader does not draw is a warning with its place,
// once per kind with a count; what is not meant to be drawn, and content for another language
// (systemLanguage), is not.
#include <catch2/catch.hpp>
#include <string>
#include <vector>

#include "pathstream/host/svg_path.hpp"
#include "pathstream/machine/input_error.hpp"

using namespace pathstream::host;

namespace {

const std::string kRoot =
    R"~(<svg xmlns="http://www.w3.org/2000/svg" width="100mm" height="100mm" viewBox="0 0 100 100">)~";

std::vector<std::string> warnings_of(const std::string& body, std::size_t* subpaths = nullptr) {
    svg::SvgReadInfo info;
    const Path p =
        parse_svg_path(kRoot + "\n" + body + "\n<line x2=\"1\"/></svg>", "w.svg", 0.01, &info);
    if (subpaths) *subpaths = p.subpaths.size() - 1;
    return info.warnings;
}

}  // namespace

TEST_CASE("svg warnings: text, images, masks, filters, markers and patterns", "[svg][warnings]") {
    const std::vector<std::string> w = warnings_of(
        R"~(<text x="1">a</text><text>b</text>
  <g><text>c</text><image width="5" height="5"/></g>
<path d="M0 0 L5 5" mask="url(#m)" filter="url(#f)" marker-end="url(#a)"/>
<defs><pattern id="p"><line x2="1"/></pattern><text>in defs: not drawn, no warning</text></defs>
<rect width="5" height="5" style="fill: url(#p); marker-start: url(#a)"/>
<flowRoot/>)~");
    CHECK(w == std::vector<std::string>{
                   "w.svg:2:1: <text> is not drawn (convert text to paths to plot it) (3 times; "
                   "the first here)",
                   "w.svg:3:20: <image> is not drawn",
                   "w.svg:4:21: mask is not applied (drawn unmasked)",
                   "w.svg:4:36: filter is not applied",
                   "w.svg:4:53: markers are not drawn (2 times; the first here)",
                   "w.svg:6:35: <pattern> content is not drawn",
                   "w.svg:7:1: <flowRoot> is not drawn (convert text to paths to plot it)",
               });
}

TEST_CASE("svg warnings: 10,000 text elements make one line", "[svg][warnings]") {
    std::string body;
    for (int i = 0; i < 10000; ++i) body += "<text>t</text>\n";
    const std::vector<std::string> w = warnings_of(body);
    CHECK(w == std::vector<std::string>{"w.svg:2:1: <text> is not drawn (convert text to paths "
                                        "to plot it) (10000 times; the first here)"});
}

TEST_CASE("svg warnings: what is not meant to be drawn is silent", "[svg][warnings]") {
    CHECK(warnings_of(R"~(<defs><path id="p" d="M0 0 L1 1"/></defs><title>t</title><desc>d</desc>
<metadata/><style>.a{stroke:red}</style><symbol id="s"><text>x</text></symbol>
<clipPath id="c"><rect width="1" height="1"/></clipPath><mask id="m"/><marker id="k"/>
<linearGradient id="g"><stop offset="0"/></linearGradient><filter id="f"/><script/>
<rect width="5" height="5" fill="url(#g)" filter="none" mask="none"/>
<sodipodi:namedview xmlns:sodipodi="http://sodipodi.sourceforge.net/DTD/sodipodi-0.dtd"/>
<text display="none">hidden</text>)~")
              .empty());
}

TEST_CASE("svg: systemLanguage and requiredExtensions outside <switch>", "[svg][warnings]") {
    std::size_t drawn = 0;
    CHECK(warnings_of(R"~(<rect width="5" height="5" systemLanguage="ru-RU"/>
<rect width="5" height="5" systemLanguage="en"/><rect width="5" height="5" systemLanguage="en-GB"/>
<rect width="5" height="5" systemLanguage="de, EN-us"/><rect width="5" height="5" systemLanguage=""/>
<rect width="5" height="5" systemLanguage="eng"/><text systemLanguage="fr">not drawn, no warning</text>
<g systemLanguage="ru"><rect width="5" height="5"/></g>
<rect width="5" height="5" requiredExtensions="http://example.org/x"/>)~",
                      &drawn)
              .empty());
    CHECK(drawn == 3);  // en, en-GB, de, EN-us
    // <switch> takes its first child that the reader's language passes
    CHECK(warnings_of(
              R"~(<switch><line x2="9" systemLanguage="ru"/><line x2="8" systemLanguage="en-US"/>
<line x2="7"/></switch>)~",
              &drawn)
              .empty());
    CHECK(drawn == 1);
    // a root for another language draws nothing at all
    try {
        parse_svg_path(R"~(<svg xmlns="http://www.w3.org/2000/svg" systemLanguage="ru-RU">
<rect width="5" height="5"/></svg>)~",
                       "r.svg");
        FAIL("a root for another language was drawn");
    } catch (const InputError& e) {
        CHECK(std::string(e.what()) == "r.svg:1:1: no drawable paths");
    }
}
