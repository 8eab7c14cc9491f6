// Reading stays linear in the document's size: each line:column lookup scans a bounded number
// of bytes (counted, not timed), and a large padded document reads as its small original.
#include <catch2/catch.hpp>
#include <random>
#include <string>

#include "pathstream/host/svg_path.hpp"
#include "pathstream/machine/input_error.hpp"

using namespace pathstream::host;

namespace {

const std::string kHead =
    "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"100mm\" height=\"100mm\" "
    "viewBox=\"0 0 100 100\">\n";

// `n` lines, each followed by `pad` bytes of comment and whitespace.
std::string lines(std::size_t n, std::size_t pad) {
    std::string s = kHead;
    for (std::size_t i = 0; i < n; ++i) {
        s += "<line x1=\"" + std::to_string(i % 97) + "\" y1=\"1\" x2=\"50\" y2=\"" +
             std::to_string(i % 89 + 2) + "\"/>\n";
        if (pad > 0) s += "<!--" + std::string(pad, '-').replace(0, 1, " ") + " -->\n";
    }
    return s;
}

// Place of byte `offset` counted from the start, as the reader once did for every element.
SourceLocation naive(const std::string& t, std::size_t offset) {
    SourceLocation at{1, 1};
    for (std::size_t i = t.rfind("\xEF\xBB\xBF", 0) == 0 ? 3 : 0; i < offset; ++i) {
        const auto c = static_cast<unsigned char>(t[i]);
        if (c == '\n') {
            ++at.line;
            at.column = 1;
        } else if ((c & 0xC0) != 0x80) {
            ++at.column;
        }
    }
    return at;
}

}  // namespace

TEST_CASE("svg: TextLocator agrees with a count from the start", "[svg]") {
    std::string t = "\xEF\xBB\xBF";
    std::mt19937 rng(3);
    const char* pieces[] = {"a", "\n", "\xC3\xA9", "\xE2\x82\xAC", "  ", "\r\n"};
    while (t.size() < 5000) t += pieces[rng() % 6];
    svg::TextLocator locator(t);
    for (std::size_t offset = 0; offset <= t.size(); offset += 1 + rng() % 37) {
        const SourceLocation a = locator.locate(offset), b = naive(t, offset);
        INFO("offset " << offset);
        CHECK(a.line == b.line);
        CHECK(a.column == b.column);
    }
    CHECK(locator.bytes_scanned() < locator.lookups() * svg::TextLocator::kStride);
}

TEST_CASE("svg: location lookups scan a bounded number of bytes", "[svg]") {
    svg::SvgReadInfo small, large;
    parse_svg_path(lines(2000, 0) + "</svg>", "t.svg", 0.01, &small);
    parse_svg_path(lines(8000, 0) + "</svg>", "t.svg", 0.01, &large);
    CHECK(small.locations >= 2000);
    CHECK(small.location_bytes_scanned < small.locations * svg::TextLocator::kStride);
    CHECK(large.location_bytes_scanned < large.locations * svg::TextLocator::kStride);
    // Four times the elements, at most a little over four times the scanning.
    CHECK(static_cast<double>(large.location_bytes_scanned) <=
          4.2 * static_cast<double>(small.location_bytes_scanned));
}

TEST_CASE("svg: a 2 MB padded document reads as its original", "[svg]") {
    const std::string plain = lines(2000, 0), padded = lines(2000, 1000);
    REQUIRE(padded.size() > 2000000);
    svg::SvgReadInfo info;
    const Path a = parse_svg_path(plain + "</svg>", "t.svg");
    const Path b = parse_svg_path(padded + "</svg>", "t.svg", 0.01, &info);
    REQUIRE(a.subpaths.size() == 2000);
    REQUIRE(b.subpaths.size() == 2000);
    for (std::size_t i = 0; i < a.subpaths.size(); ++i) {
        REQUIRE(a.subpaths[i].points == b.subpaths[i].points);
        REQUIRE(b.subpaths[i].location.line == 2 + 2 * i);
    }
    CHECK(info.location_bytes_scanned < info.locations * svg::TextLocator::kStride);
    // An error after the last line names its place at the end of the 2 MB.
    try {
        parse_svg_path(padded + "  <path d=\"M 1 1 X\"/></svg>", "t.svg");
        FAIL("no error");
    } catch (const InputError& e) {
        CHECK(std::string(e.what()) ==
              "t.svg:4002:9: path data: unknown command 'X' at character 7");
    }
}
