// The CSV point reader: headers, comments, whitespace, and each broken file with its exact
// message.
#include <catch2/catch.hpp>
#include <string>

#include "pathstream/host/csv_path.hpp"
#include "pathstream/machine/input_error.hpp"

using namespace pathstream::host;

namespace {

Path csv(const std::string& text, PathBasis basis = PathBasis::kBSpline, bool closed = false) {
    return parse_csv_path(text, "t.csv", basis, closed);
}

std::string error_of(const std::string& text, PathBasis basis = PathBasis::kBSpline,
                     bool closed = false) {
    try {
        csv(text, basis, closed);
    } catch (const InputError& e) {
        return e.what();
    }
    return "no error";
}

std::string source_dir() {
#ifdef PATHSTREAM_SOURCE_DIR
    return PATHSTREAM_SOURCE_DIR;
#else
    const std::string here = __FILE__;
    return here.substr(0, here.rfind("/tests/host/"));
#endif
}

}  // namespace

TEST_CASE("CSV: one point per line after an optional header", "[host][csv]") {
    const Path p = csv("x,y\n0,0\n1,2.5\n3,4\n");
    REQUIRE(p.axes == 2);
    REQUIRE(p.subpaths.size() == 1);
    const Subpath& sp = p.subpaths[0];
    CHECK(sp.basis == PathBasis::kBSpline);
    CHECK_FALSE(sp.closed);
    CHECK(sp.feed == 0.0);
    CHECK(sp.location.line == 2);
    CHECK(sp.location.column == 1);
    REQUIRE(sp.points.size() == 3);
    CHECK(sp.points[1] == PathPoint{1.0, 2.5});
    CHECK(sp.points[2] == PathPoint{3.0, 4.0});

    const Path q = csv("0,0\n1,2\n", PathBasis::kPolyline);  // no header
    CHECK(q.subpaths[0].points.size() == 2);
    CHECK(q.subpaths[0].basis == PathBasis::kPolyline);
    CHECK(q.subpaths[0].location.line == 1);
}

TEST_CASE("CSV: comments, blank lines, whitespace, CRLF, a BOM, signs and exponents",
          "[host][csv]") {
    const Path p =
        csv("\xEF\xBB\xBF# a comment\r\n\r\n   \t\r\n  x , y , z\r\n  1 , 2 ,3\r\n  # another\r\n"
            "+4,\t5e-1, -6E2\r\n.5,7.,1e-400\r\n");
    REQUIRE(p.axes == 3);
    const Subpath& sp = p.subpaths[0];
    REQUIRE(sp.points.size() == 3);
    CHECK(sp.location.line == 5);
    CHECK(sp.location.column == 3);
    CHECK(sp.points[0] == PathPoint{1, 2, 3});
    CHECK(sp.points[1] == PathPoint{4, 0.5, -600});
    CHECK(sp.points[2] == PathPoint{0.5, 7, 0});  // 1e-400 underflows to 0
}

TEST_CASE("CSV: 1 to 8 columns, the basis and closed flag are the caller's", "[host][csv]") {
    const Path one = csv("t\n1\n2\n3\n", PathBasis::kCatmullRom, true);
    CHECK(one.axes == 1);
    CHECK(one.subpaths[0].basis == PathBasis::kCatmullRom);
    CHECK(one.subpaths[0].closed);
    const Path eight = csv("1,2,3,4,5,6,7,8\n8,7,6,5,4,3,2,1\n", PathBasis::kPolyline);
    CHECK(eight.axes == 8);
    const Path bezier = csv("0,0\n1,1\n2,1\n3,0\n", PathBasis::kBezier);
    CHECK(bezier.subpaths[0].points.size() == 4);
    const Path closed_bezier = csv("0,0\n1,1\n2,1\n", PathBasis::kBezier, true);
    CHECK(closed_bezier.subpaths[0].closed);
}

TEST_CASE("CSV: the example star reads as a closed polyline", "[host][csv]") {
    const Path p = load_csv_path(source_dir() + "/examples/star.csv", PathBasis::kPolyline, true);
    REQUIRE(p.axes == 2);
    REQUIRE(p.subpaths[0].points.size() == 10);
    CHECK(p.subpaths[0].points[0] == PathPoint{50, 90});
    CHECK(p.subpaths[0].location.line == 4);
}

TEST_CASE("CSV: bad fields name line, column and the problem", "[host][csv]") {
    CHECK(error_of("0,0\n1,abc\n") == "t.csv:2:3: \"abc\" is not a number");
    CHECK(error_of("0,0\n1, 2x\n") == "t.csv:2:4: \"2x\" is not a number");
    CHECK(error_of("0,0\n1,++2\n") == "t.csv:2:3: \"++2\" is not a number");
    CHECK(error_of("x,1\n") == "t.csv:1:1: \"x\" is not a number");  // not a header: 1 is a number
    CHECK(error_of("0,0\n1,\n") == "t.csv:2:3: empty field (expected a number)");
    CHECK(error_of("0,0\n ,1\n") == "t.csv:2:2: empty field (expected a number)");
    CHECK(error_of("0,0\n1, inf\n") == "t.csv:2:4: coordinate is not finite");
    CHECK(error_of("0,0\nnan,1\n") == "t.csv:2:1: coordinate is not finite");
    CHECK(error_of("0,0\n1,1e400\n") ==
          "t.csv:2:3: number 1e400 is out of range (not finite as a double)");
    CHECK(error_of("0,0\n1,-0.000001e999999999999\n") ==
          "t.csv:2:3: number -0.000001e999999999999 is out of range (not finite as a double)");
    CHECK(error_of("0,0\n2e6,0\n") ==
          "t.csv:2:1: coordinate 2e+06 is out of range (|value| <= 1e+06 mm)");
    CHECK(error_of("0,0\n0,-1000000.5\n") ==
          "t.csv:2:3: coordinate -1e+06 is out of range (|value| <= 1e+06 mm)");
}

TEST_CASE("CSV: column counts", "[host][csv]") {
    CHECK(error_of("0,0\n1,1,1\n") == "t.csv:2:5: point has 3 coordinates, expected 2");
    CHECK(error_of("0,0,0\n1, 1\n") == "t.csv:2:4: point has 2 coordinates, expected 3");
    CHECK(error_of("x,y,z\n1,1\n") == "t.csv:2:3: point has 2 coordinates, expected 3");
    CHECK(error_of("0,0\n1,1,\n") == "t.csv:2:5: point has 3 coordinates, expected 2");
    CHECK(error_of("1,2,3,4,5,6,7,8,9\n") == "t.csv:1:17: point has 9 coordinates (1 to 8 axes)");
    CHECK(error_of("a,b,c,d,e,f,g,h,i\n") == "t.csv:1:17: header has 9 columns (1 to 8 axes)");
}

TEST_CASE("CSV: too few points for the basis", "[host][csv]") {
    CHECK(error_of("x,y\n1,2\n") == "t.csv:2:1: open bspline needs at least 2 points, got 1");
    CHECK(error_of("x,y\n") == "t.csv: open bspline needs at least 2 points, got 0");
    CHECK(error_of("") == "t.csv: open bspline needs at least 2 points, got 0");
    CHECK(error_of("0,0\n1,1\n", PathBasis::kCatmullRom, true) ==
          "t.csv:1:1: closed catmull-rom needs at least 3 points, got 2");
    CHECK(error_of("0,0\n1,1\n", PathBasis::kPolyline, true) ==
          "t.csv:1:1: closed polyline needs at least 3 points, got 2");
    CHECK(error_of("0,0\n1,1\n2,2\n", PathBasis::kBezier) ==
          "t.csv:1:1: open bezier needs 3k + 1 points (k >= 1), got 3");
    CHECK(error_of("0,0\n1,1\n2,2\n3,3\n", PathBasis::kBezier, true) ==
          "t.csv:1:1: closed bezier needs 3k points (k >= 1), got 4");
}

TEST_CASE("CSV: a missing file is an input error naming it", "[host][csv]") {
    CHECK_THROWS_WITH(load_csv_path("/nonexistent/p.csv", PathBasis::kPolyline, false),
                      "/nonexistent/p.csv: cannot open file");
}
