// Flat point storage of a subpath (point_list.hpp).
#include "pathstream/host/point_list.hpp"

#include <algorithm>
#include <functional>
#include <stdexcept>
#include <string>

namespace pathstream::host {

bool operator==(PointRef a, PointRef b) {
    return a.size() == b.size() && std::equal(a.begin(), a.end(), b.begin());
}

PointList::PointList(std::initializer_list<PathPoint> points) {
    if (points.size() > 0) reserve(points.size(), points.begin()->size());
    for (const PathPoint& p : points) push_back(p);
}

PointList::PointList(const std::vector<PathPoint>& points) {
    if (!points.empty()) reserve(points.size(), points.front().size());
    for (const PathPoint& p : points) push_back(p);
}

void PointList::reserve(std::size_t points, std::size_t axes) {
    if (axes_ == 0 && coords_.empty()) axes_ = axes;
    coords_.reserve(points * axes_);
}

void PointList::push_back(PointRef p) {
    if (axes_ == 0 && coords_.empty()) axes_ = p.size();
    if (p.size() != axes_ || p.empty()) {
        throw std::invalid_argument("a point has " + std::to_string(p.size()) +
                                    " coordinates, expected " + std::to_string(axes_));
    }
    // p may view this list: inserting from our own storage is not allowed (it may move).
    const std::less<const double*> before;
    if (!before(p.data(), coords_.data()) && before(p.data(), coords_.data() + coords_.size())) {
        const PathPoint copy = p.vector();
        coords_.insert(coords_.end(), copy.begin(), copy.end());
        return;
    }
    coords_.insert(coords_.end(), p.begin(), p.end());
}

void PointList::append(const PointList& other, std::size_t first, std::size_t last) {
    if (first >= last) return;
    if (axes_ == 0 && coords_.empty()) axes_ = other.axes_;
    if (other.axes_ != axes_) throw std::invalid_argument("appending points of another axis count");
    if (&other == this) {
        const std::vector<double> copy(coords_.begin() + static_cast<std::ptrdiff_t>(first * axes_),
                                       coords_.begin() + static_cast<std::ptrdiff_t>(last * axes_));
        coords_.insert(coords_.end(), copy.begin(), copy.end());
        return;
    }
    coords_.insert(coords_.end(),
                   other.coords_.begin() + static_cast<std::ptrdiff_t>(first * axes_),
                   other.coords_.begin() + static_cast<std::ptrdiff_t>(last * axes_));
}

void PointList::prepend(const PointList& other, std::size_t first, std::size_t last) {
    if (first >= last) return;
    if (axes_ == 0 && coords_.empty()) axes_ = other.axes_;
    if (other.axes_ != axes_ || &other == this)
        throw std::invalid_argument("prepending points of another list");
    coords_.insert(coords_.begin(),
                   other.coords_.begin() + static_cast<std::ptrdiff_t>(first * axes_),
                   other.coords_.begin() + static_cast<std::ptrdiff_t>(last * axes_));
}

void PointList::erase_front(std::size_t count) {
    coords_.erase(coords_.begin(),
                  coords_.begin() + static_cast<std::ptrdiff_t>(std::min(count, size()) * axes_));
}

void PointList::reverse(std::size_t first) {
    if (first >= size()) return;
    // Reversing every value reverses the point order and each point's coordinates; the second
    // pass puts the coordinates back in axis order.
    const auto begin = coords_.begin() + static_cast<std::ptrdiff_t>(first * axes_);
    std::reverse(begin, coords_.end());
    for (auto p = begin; p != coords_.end(); p += static_cast<std::ptrdiff_t>(axes_)) {
        std::reverse(p, p + static_cast<std::ptrdiff_t>(axes_));
    }
}

void PointList::rotate(std::size_t shift) {
    if (empty()) return;
    std::rotate(coords_.begin(),
                coords_.begin() + static_cast<std::ptrdiff_t>((shift % size()) * axes_),
                coords_.end());
}

std::vector<PathPoint> PointList::vectors() const {
    std::vector<PathPoint> out;
    out.reserve(size());
    for (PointRef p : *this) out.push_back(p.vector());
    return out;
}

}  // namespace pathstream::host
