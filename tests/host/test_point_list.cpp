// PointList (point_list.hpp): flat storage of a subpath's points and the reorderings the path
// order makes of it, against the same operations on a std::vector of points.
#include <algorithm>
#include <catch2/catch.hpp>
#include <stdexcept>
#include <vector>

#include "pathstream/host/point_list.hpp"

using namespace pathstream::host;

namespace {

/// Points (i, 10 i, 100 i) for i in [0, n): 3 axes, every coordinate distinct.
std::vector<PathPoint> numbered(std::size_t n) {
    std::vector<PathPoint> out;
    for (std::size_t i = 0; i < n; ++i) {
        const double v = static_cast<double>(i);
        out.push_back({v, 10 * v, 100 * v});
    }
    return out;
}

}  // namespace

TEST_CASE("point list: size, views and the axes of the first point", "[order][points]") {
    PointList list;
    CHECK(list.empty());
    list.push_back({1.0, 2.0});
    list.push_back(PathPoint{3, 4});
    CHECK(list.axes() == 2);
    CHECK(list.size() == 2);
    CHECK(list.coords() == std::vector<double>{1, 2, 3, 4});
    CHECK(list.back() == PathPoint{3, 4});
    list[0][1] = 5;  // a writable view writes into the list
    CHECK(list.front() == PathPoint{1, 5});
    CHECK_THROWS_AS(list.push_back({1.0, 2.0, 3.0}), std::invalid_argument);
    CHECK(list.size() == 2);
    std::size_t visited = 0;
    for (PointRef p : list) visited += p.size();
    CHECK(visited == 4);
}

TEST_CASE("point list: reverse, rotate and appending its own point match a vector",
          "[order][points]") {
    for (std::size_t n : {1u, 2u, 5u, 8u}) {
        const std::vector<PathPoint> v = numbered(n);
        for (std::size_t first : {0u, 1u}) {
            PointList list(v);
            list.reverse(first);
            std::vector<PathPoint> expected = v;
            if (first < n)
                std::reverse(expected.begin() + static_cast<std::ptrdiff_t>(first), expected.end());
            CHECK(list.vectors() == expected);
        }
        for (std::size_t shift = 0; shift <= n; ++shift) {
            PointList list(v);
            list.rotate(shift);
            std::vector<PathPoint> expected = v;
            std::rotate(expected.begin(), expected.begin() + static_cast<std::ptrdiff_t>(shift % n),
                        expected.end());
            CHECK(list.vectors() == expected);
        }
        PointList list(v);
        list.push_back(list.front());  // may reallocate while reading its own storage
        CHECK(list.size() == n + 1);
        CHECK(list.back() == v.front());
        list.erase_front(1);
        list.append(PointList(v), 0, n);
        CHECK(list.size() == 2 * n);
        CHECK(list[n - 1] == v.front());
    }
}
