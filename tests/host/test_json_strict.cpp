// Strict JSON: what nlohmann::json lets pass is refused with file:line:col, and locating
// values costs a bounded number of passes over the document, however many there are.
#include <catch2/catch.hpp>

#include "pathstream/host/json_path.hpp"
#include "pathstream/machine/input_error.hpp"
#include "pathstream/machine/json_document.hpp"
#include "pathstream/machine/json_locate.hpp"

using namespace pathstream::host;

namespace {
std::string error_of(const std::string& text) {
    try {
        parse_json_path(text, "t.json");
    } catch (const InputError& e) {
        return e.what();
    }
    return "no error";
}

// `count` subpaths of three points, one subpath a line: about 46 bytes each.
std::string subpaths_document(std::size_t count) {
    std::string text = "{\"subpaths\": [\n";
    for (std::size_t i = 0; i < count; ++i) {
        const std::string x = std::to_string(i % 1000);
        text += "  {\"points\": [[" + x + ", 0], [" + x + ", 1], [" + x + ", 2]]}";
        text += i + 1 < count ? ",\n" : "\n";
    }
    return text + "]}\n";
}
}  // namespace

TEST_CASE("duplicate keys are errors", "[host][json]") {
    CHECK(error_of("{\"points\": [[0, 0], [1, 1]],\n \"points\": [[0, 0], [2, 2]]}") ==
          "t.json:2:2: duplicate key in one object");
    // Escapes decode before comparing: "\u0062asis" is "basis".
    CHECK(error_of("{\"subpaths\": [{\"basis\": \"bezier\", \"\\u0062asis\": \"polyline\", "
                   "\"points\": [[0,0],[1,1]]}]}") == "t.json:1:35: duplicate key in one object");
    // The same key in two objects is fine.
    CHECK(error_of("{\"subpaths\": [{\"points\": [[0,0],[1,1]]}, {\"points\": [[0,0],[1,1]]}]}") ==
          "no error");
}

TEST_CASE("bytes after the document are errors, after a NUL too", "[host][json]") {
    CHECK(error_of(std::string("{\"points\": [[0, 0], [1, 1]]}\n\0{\"x\": 1}", 37)) ==
          "t.json:2:1: invalid JSON: a NUL byte after the document");
    CHECK(error_of("{\"points\": [[0, 0], [1, 1]]}  \n  x")
              .rfind("t.json:2:3: invalid JSON: syntax error", 0) == 0);
    CHECK(error_of("{\"points\": [[0, 0], [1, 1]]}\n\t \r\n") == "no error");
    // A NUL inside the document ends it early: a syntax error where it sits.
    CHECK(error_of(std::string("{\"points\": [[0, 0]\0, [1, 1]]}", 29))
              .rfind("t.json:1:19: invalid JSON: syntax error", 0) == 0);
}

TEST_CASE("reading 20000 subpaths scans the text a bounded number of times", "[host][json]") {
    const std::string text = subpaths_document(20000);
    const std::size_t before = json_bytes_scanned();
    const Path path = parse_json_path(text, "t.json");
    const std::size_t scanned = json_bytes_scanned() - before;
    REQUIRE(path.subpaths.size() == 20000);
    CHECK(path.subpaths[19999].location.line == 20001);
    CHECK(path.subpaths[19999].location.column == 3);
    // Strictness checks and locations: one index, plus one for the checks; never one per subpath.
    CHECK(scanned <= 4 * text.size());
    CHECK(scanned >= text.size());
}

TEST_CASE("a JSON index finds values by pointer and bytes by line", "[host][json]") {
    const JsonIndex index("{\"a/b\": [1, {\"~k\": \"v\"}],\n \"c\": {}}");
    CHECK(index.locate("").column == 1);
    CHECK(index.locate("/a~1b/1/~0k").column == 20);
    CHECK(index.locate("/c").line == 2);
    CHECK(index.locate("/c").column == 7);
    CHECK(index.locate("/a~1b/2").line == 0);
    CHECK(index.locate("/zz").line == 0);
    CHECK(index.location_of(26).line == 2);
    CHECK(index.location_of(26).column == 1);
    CHECK(index.location_of(25).line == 1);
    CHECK_FALSE(index.duplicate_key());
    CHECK_FALSE(index.trailing_byte());
}

TEST_CASE("points arrays read flat report what the document tree did, where it did",
          "[host][json]") {
    // Rows of numbers are read flat; their errors are found after parsing, located as before.
    CHECK(error_of("{\"points\": [[0, 0],\n [1, 1, 2]]}") ==
          "t.json:2:2: point has 3 coordinates, expected 2");
    CHECK(
        error_of(
            "{\"subpaths\": [{\"points\": [[0, 0], [1, 1]]},\n {\"points\": [[0, 0], [1, 1e7]]}]}")
            .rfind("t.json:2:26: coordinate 1e+07 is out of range", 0) == 0);
    CHECK(error_of("{\"points\": [[], [1, 1]]}") ==
          "t.json:1:13: point has 0 coordinates (1 to 8 axes)");
    // Anything else in them goes into the tree from where it appears, rows read so far too.
    CHECK(error_of("{\"points\": [[0, 0], [1, \"x\"]]}") ==
          "t.json:1:25: coordinate must be a number");
    CHECK(error_of("{\"points\": [[0, 0], 7]}") ==
          "t.json:1:21: point must be an array of coordinates");
    CHECK(error_of("{\"points\": [[0, 0], [[1], 1]]}") ==
          "t.json:1:22: coordinate must be a number");
    CHECK(error_of("{\"points\": [[0, 0], {\"x\": 1}]}") ==
          "t.json:1:21: point must be an array of coordinates");
    // Elsewhere, arrays of arrays stay in the tree (knots are numbers, not rows).
    CHECK(error_of("{\"points\": [[0, 0], [1, 1]], \"closed\": [[1]]}") ==
          "t.json:1:40: closed must be true or false");
    // A flat array is an empty one in the document: the reader still sees the points.
    FlatNumberArrays flat;
    flat.where = {"/subpaths/*/points"};
    const nlohmann::json document = parse_json_document(
        "{\"subpaths\": [{\"points\": [[0, 1], [2, 3, 4]]}, {\"points\": 5}]}", "t.json", &flat);
    CHECK(document["subpaths"][0]["points"] == nlohmann::json::array());
    CHECK(document["subpaths"][1]["points"] == 5);
    REQUIRE(flat.found.count("/subpaths/0/points") == 1);
    CHECK(flat.found["/subpaths/0/points"].values == std::vector<double>{0, 1, 2, 3, 4});
    CHECK(flat.found["/subpaths/0/points"].widths == std::vector<std::uint8_t>{2, 3});
}

TEST_CASE("JSON nested past the reader's limit is refused at the first bracket too deep",
          "[host][json]") {
    // 8 million levels once took 84 s and 1.9 GB before the error; now one pass over the bytes.
    const std::string deep = std::string(8'000'000, '[') + std::string(8'000'000, ']');
    try {
        (void)parse_json_document(deep, "t.json");
        FAIL("parsed 8 million levels");
    } catch (const InputError& e) {
        CHECK(std::string(e.what()) ==
              "t.json:1:257: invalid JSON: nested more than 256 levels deep (the reader's limit)");
    }
    // Brackets inside strings do not count; 256 levels are read.
    const std::string in_string = R"({"units": "mm", "note": ")" + std::string(1000, '[') +
                                  R"(", "points": [[0, 0], [1, 1]]})";
    CHECK_NOTHROW(parse_json_document(in_string, "t.json"));
    const std::string at_limit = std::string(256, '[') + std::string(256, ']');
    CHECK_NOTHROW(parse_json_document(at_limit, "t.json"));
    const std::string escaped = R"({"a": "\"[[[", "b": 1})";
    CHECK_NOTHROW(parse_json_document(escaped, "t.json"));
}

TEST_CASE("an error quoting a huge token stays short", "[host][json]") {
    // A number of a million digits: the message names it, cut in the middle.
    const std::string text =
        R"({"units": "mm", "points": [[0, 1)" + std::string(1'000'000, '0') + "]]}";
    const std::string message = error_of(text);
    INFO(message.substr(0, 200));
    CHECK(message.rfind("t.json:1:", 0) == 0);
    CHECK(message.size() < 1200);
    CHECK(message.find("bytes left out") != std::string::npos);
}
