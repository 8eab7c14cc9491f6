// A subpath's points stored flat: one array of doubles, `axes` per point, and views of one
// point into it. A 2-axis point costs 16 bytes here instead of ~56 as a std::vector of its own
// (heap block, its header and the vector), which is what lets a 10^6-point file load in a few
// tens of MB.
#pragma once

#include <cstddef>
#include <initializer_list>
#include <iterator>
#include <type_traits>
#include <vector>

namespace pathstream::host {

/// One point: one coordinate per axis, in millimetres (an owned copy).
using PathPoint = std::vector<double>;

/// A view of one point's coordinates (T = const double: read-only, T = double: writable).
/// Valid while the PointList it came from is not resized. Copies of a view are views of the
/// same point; assign() copies coordinates into it.
template <class T>
class BasicPointRef {
public:
    BasicPointRef(T* data, std::size_t size) : data_(data), size_(size) {}
    /// Any owned point is viewed read-only; no copy.
    template <class U = T, class = std::enable_if_t<std::is_const_v<U>>>
    BasicPointRef(const PathPoint& p)
        : data_(p.data()), size_(p.size()) {}  // NOLINT: implicit by design
    /// A writable view is also a read-only one.
    template <class U = T, class = std::enable_if_t<std::is_const_v<U>>>
    BasicPointRef(const BasicPointRef<double>& p) : data_(p.data()), size_(p.size()) {}  // NOLINT

    std::size_t size() const { return size_; }
    bool empty() const { return size_ == 0; }
    T& operator[](std::size_t i) const { return data_[i]; }
    T* data() const { return data_; }
    T* begin() const { return data_; }
    T* end() const { return data_ + size_; }
    /// An owned copy of the coordinates.
    PathPoint vector() const { return PathPoint(data_, data_ + size_); }
    operator PathPoint() const { return vector(); }  // NOLINT: implicit, as a point was a vector
    /// Copies `p`'s coordinates into the viewed point (the sizes must be equal).
    void assign(BasicPointRef<const double> p) const {
        for (std::size_t i = 0; i < size_ && i < p.size(); ++i) data_[i] = p[i];
    }

private:
    T* data_;
    std::size_t size_;
};

using PointRef = BasicPointRef<const double>;  ///< read-only view of one point
using PointMutRef = BasicPointRef<double>;     ///< writable view of one point

/// Equal coordinate counts and coordinates.
bool operator==(PointRef a, PointRef b);
inline bool operator!=(PointRef a, PointRef b) {
    return !(a == b);
}
/// Needed beside the PointRef form: a PathPoint converts both to a PointRef and from one.
inline bool operator==(PointRef a, const PathPoint& b) {
    return a == PointRef(b);
}
inline bool operator==(const PathPoint& a, PointRef b) {
    return PointRef(a) == b;
}
inline bool operator!=(PointRef a, const PathPoint& b) {
    return !(a == PointRef(b));
}
inline bool operator!=(const PathPoint& a, PointRef b) {
    return !(PointRef(a) == b);
}
inline bool operator==(PointMutRef a, const PathPoint& b) {
    return PointRef(a) == PointRef(b);
}
inline bool operator!=(PointMutRef a, const PathPoint& b) {
    return !(PointRef(a) == PointRef(b));
}

/// The points of one subpath, stored flat: every point has axes() coordinates. The number of
/// axes is set by the constructor or by the first point added; a point of another size is
/// refused (std::invalid_argument). Works like a std::vector of points where that is cheap
/// (size, [], front, back, push_back, iteration) and has the reorderings the path order needs
/// (reverse, rotate) working on the flat array.
class PointList {
public:
    /// Iterator over the points, dereferencing to a view (R: PointRef or PointMutRef).
    template <class R, class D>
    class Iterator {
    public:
        using iterator_category = std::forward_iterator_tag;
        using value_type = R;
        using difference_type = std::ptrdiff_t;
        using pointer = void;
        using reference = R;
        Iterator(D* at, std::size_t axes) : at_(at), axes_(axes) {}
        R operator*() const { return R(at_, axes_); }
        Iterator& operator++() {
            at_ += axes_;
            return *this;
        }
        Iterator operator++(int) {
            Iterator before = *this;
            ++*this;
            return before;
        }
        bool operator==(const Iterator& o) const { return at_ == o.at_; }
        bool operator!=(const Iterator& o) const { return at_ != o.at_; }

    private:
        D* at_;
        std::size_t axes_;
    };
    using const_iterator = Iterator<PointRef, const double>;
    using iterator = Iterator<PointMutRef, double>;

    PointList() = default;
    /// An empty list of points of `axes` coordinates.
    explicit PointList(std::size_t axes) : axes_(axes) {}
    /// The given points, copied (tests and small paths: `points = {{0, 0}, {1, 2}}`).
    PointList(std::initializer_list<PathPoint> points);
    PointList(const std::vector<PathPoint>& points);  // NOLINT: implicit, as the points were one

    std::size_t axes() const { return axes_; }
    std::size_t size() const { return axes_ == 0 ? 0 : coords_.size() / axes_; }
    bool empty() const { return coords_.empty(); }
    /// Every coordinate, point after point (size() * axes() values).
    const std::vector<double>& coords() const { return coords_; }

    PointRef operator[](std::size_t i) const { return PointRef(coords_.data() + i * axes_, axes_); }
    PointMutRef operator[](std::size_t i) { return PointMutRef(coords_.data() + i * axes_, axes_); }
    PointRef front() const { return (*this)[0]; }
    PointMutRef front() { return (*this)[0]; }
    PointRef back() const { return (*this)[size() - 1]; }
    PointMutRef back() { return (*this)[size() - 1]; }
    const_iterator begin() const { return {coords_.data(), axes_}; }
    const_iterator end() const { return {coords_.data() + coords_.size(), axes_}; }
    iterator begin() { return {coords_.data(), axes_}; }
    iterator end() { return {coords_.data() + coords_.size(), axes_}; }

    /// Room for `points` points of `axes` coordinates (sets axes() when there is none yet).
    void reserve(std::size_t points, std::size_t axes);
    /// Room for `points` points; the axes must be known (else nothing is reserved).
    void reserve(std::size_t points) { coords_.reserve(points * axes_); }
    /// Appends a copy of `p` (from this list too). Throws std::invalid_argument when its size
    /// is not axes() (or it has no coordinates).
    void push_back(PointRef p);
    void push_back(std::initializer_list<double> p) { push_back(PointRef(p.begin(), p.size())); }
    /// Appends points [first, last) of `other` (same axes; may be this list).
    void append(const PointList& other, std::size_t first, std::size_t last);
    /// Puts points [first, last) of `other` (another list, same axes) in front.
    void prepend(const PointList& other, std::size_t first, std::size_t last);
    /// Drops the first `count` points.
    void erase_front(std::size_t count);
    void pop_back() { coords_.resize(coords_.size() - axes_); }
    void clear() { coords_.clear(); }
    /// Points [first, size()) in reverse order, the ones before as they are.
    void reverse(std::size_t first = 0);
    /// The points rotated left by `shift`: point `shift` becomes the first.
    void rotate(std::size_t shift);
    /// The points as owned copies (tests, small paths).
    std::vector<PathPoint> vectors() const;

    friend bool operator==(const PointList& a, const PointList& b) {
        return a.size() == b.size() && (a.empty() || a.axes_ == b.axes_) && a.coords_ == b.coords_;
    }
    friend bool operator!=(const PointList& a, const PointList& b) { return !(a == b); }

private:
    std::size_t axes_ = 0;
    std::vector<double> coords_;
};

}  // namespace pathstream::host
