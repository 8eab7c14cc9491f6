// The JSON path reader: valid documents, and each kind of broken one with its exact message.
#include <catch2/catch.hpp>

#include "pathstream/host/json_path.hpp"
#include "pathstream/machine/input_error.hpp"

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
}  // namespace

TEST_CASE("a one-subpath document with defaults", "[host][json]") {
    const Path p = parse_json_path(R"({"points": [[0, 0], [1, 2.5], [3, 4]]})", "t.json");
    REQUIRE(p.axes == 2);
    REQUIRE(p.subpaths.size() == 1);
    CHECK(p.subpaths[0].basis == PathBasis::kBSpline);
    CHECK_FALSE(p.subpaths[0].closed);
    CHECK(p.subpaths[0].points[1] == PathPoint{1.0, 2.5});
}

TEST_CASE("subpaths inherit and override basis and closed, inches convert", "[host][json]") {
    const Path p = parse_json_path(R"({"units": "in", "basis": "catmull-rom", "closed": true,
        "subpaths": [{"points": [[0,0,0],[1,0,0],[1,1,0]]},
                     {"basis": "bezier", "closed": false, "points": [[0,0,1],[1,0,1],[1,1,1],[0,1,1]]}]})",
                                   "t.json");
    REQUIRE(p.axes == 3);
    REQUIRE(p.subpaths.size() == 2);
    CHECK(p.subpaths[0].basis == PathBasis::kCatmullRom);
    CHECK(p.subpaths[0].closed);
    CHECK(p.subpaths[1].basis == PathBasis::kBezier);
    CHECK_FALSE(p.subpaths[1].closed);
    CHECK(p.subpaths[1].points[2][1] == Approx(25.4));
}

TEST_CASE("broken documents name file, line, column and the problem", "[host][json]") {
    CHECK(error_of("{\n  \"points\": [[0, 0],\n    [1, \"x\"]]\n}") ==
          "t.json:3:9: coordinate must be a number");
    CHECK(error_of("{\"points\": [[0, 0], [1, 2]], \"colour\": 1}") ==
          "t.json:1:40: unknown key \"colour\" (expected one of: basis, closed, points, subpaths, "
          "surfaces, units, view)");
    CHECK(error_of("{\"points\": [[0, 0], [1, 2]]\n,}")
              .rfind("t.json:2:2: invalid JSON: syntax error", 0) == 0);
    CHECK(error_of("{\"points\": [[0, 0], [1e400, 2]]}") ==
          "t.json:1:22: number 1e400 is out of range (not finite as a double)");
    CHECK(error_of("{\"points\": [[0, 0], [2e6, 2]]}") ==
          "t.json:1:22: coordinate 2e+06 is out of range (|value| <= 1e+06 mm)");
    CHECK(error_of("{\"points\": [[0, 0]]}") ==
          "t.json:1:12: open bspline needs at least 2 points, got 1");
    CHECK(error_of("{\"closed\": true, \"points\": [[0, 0], [1, 1]]}") ==
          "t.json:1:28: closed bspline needs at least 3 points, got 2");
    CHECK(error_of("{\"basis\": \"bezier\", \"points\": [[0,0],[1,1],[2,2]]}") ==
          "t.json:1:31: open bezier needs 3k + 1 points (k >= 1), got 3");
    CHECK(error_of("{\"basis\": \"nurbs\", \"points\": [[0,0],[1,1]]}") ==
          "t.json:1:11: basis nurbs is given per subpath, with its degree and knots");
    CHECK(error_of("{\"basis\": \"spline\", \"points\": [[0,0],[1,1]]}") ==
          "t.json:1:11: unknown basis \"spline\" (expected bspline, catmull-rom, bezier, polyline, "
          "nurbs or function)");
    CHECK(error_of("{\"basis\": \"function\", \"points\": [[0,0],[1,1]]}") ==
          "t.json:1:11: basis function is given per subpath, with its x, y (z) and t");
    CHECK(error_of(
              "{\"subpaths\": [{\"basis\": \"function\", \"x\": \"t\", \"y\": \"t\", \"z\": \"t\", "
              "\"t\": [0, 1]}, {\"points\": [[0,0],[1,1]]}]}") ==
          "t.json:1:93: point has 2 coordinates, expected 3");
    CHECK(error_of("{\"points\": [[0,0],[1,1,1]]}") ==
          "t.json:1:19: point has 3 coordinates, expected 2");
    CHECK(error_of("{\"points\": [[0,0],[1,1]], \"subpaths\": []}") ==
          "t.json:1:1: give either \"points\" (one subpath) or \"subpaths\", not both or neither");
    CHECK(error_of("{\"units\": \"cm\", \"points\": [[0,0],[1,1]]}") ==
          "t.json:1:11: unknown units \"cm\" (expected mm or in)");
    CHECK(error_of("[1, 2]") == "t.json:1:1: a path file must be a JSON object");
}

TEST_CASE("a missing file is an input error naming it", "[host][json]") {
    CHECK_THROWS_WITH(load_json_path("/nonexistent/p.json"),
                      "/nonexistent/p.json: cannot open file");
}
