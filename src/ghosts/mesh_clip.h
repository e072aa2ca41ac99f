#pragma once
// Clipping the shaped ghosts' mesh triangles by their apertures' margins, shared by the table's build
// (each mesh's flux) and the renderer (the polygons it draws). Internal.

#include <glm/vec3.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <utility>

namespace ff::ghosts {

constexpr std::size_t kMaxConstraints = 40;              // apertures' margins cutting one triangle
constexpr std::size_t kMaxPolygon = kMaxConstraints + 3; // vertices of a clipped triangle

// A triangle with per-vertex constraint values (linear across it), clipped to where all are >= 0.
// Polygon vertices are barycentric coordinates. Returns the lit share of the triangle's area.
class TriangleClipper {
  public:
    // c[k][i]: constraint k at vertex i. The clipped polygon is left in poly() (barycentrics).
    double clip(const std::array<double, 3>* c, std::size_t constraints) {
        count_ = 3;
        a_[0] = {1, 0, 0};
        a_[1] = {0, 1, 0};
        a_[2] = {0, 0, 1};
        for (std::size_t k = 0; k < constraints && count_ > 0; ++k) {
            const auto& ck = c[k];
            std::size_t m = 0;
            for (std::size_t p = 0; p < count_; ++p) {
                const glm::dvec3& A = a_[p];
                const glm::dvec3& B = a_[(p + 1) % count_];
                const double va = A.x * ck[0] + A.y * ck[1] + A.z * ck[2];
                const double vb = B.x * ck[0] + B.y * ck[1] + B.z * ck[2];
                if (va >= 0.0 && m < kMaxPolygon) b_[m++] = A;
                if ((va >= 0.0) != (vb >= 0.0) && m < kMaxPolygon) b_[m++] = A + (B - A) * (va / (va - vb));
            }
            std::swap(a_, b_);
            count_ = m;
        }
        if (count_ < 3) return 0.0;
        // Area in the (b1, b2) plane relative to the whole triangle's 1/2.
        double area = 0.0;
        for (std::size_t p = 0; p < count_; ++p) {
            const glm::dvec3& A = a_[p];
            const glm::dvec3& B = a_[(p + 1) % count_];
            area += A.y * B.z - B.y * A.z;
        }
        return std::clamp(std::abs(area), 0.0, 1.0);
    }
    std::size_t size() const { return count_; }
    const glm::dvec3& operator[](std::size_t p) const { return a_[p]; }

  private:
    std::array<glm::dvec3, kMaxPolygon> a_, b_;
    std::size_t count_ = 0;
};

// The two triangles of a grid cell as corner indices (0: (i, j), 1: (i+1, j), 2: (i, j+1), 3: (i+1,
// j+1)) whose corners are all traced; {4, 4, 4} stands for none. The cell is split along the
// diagonal that keeps a triangle when one corner is lost.
inline std::array<std::array<int, 3>, 2> cellTriangles(bool c0, bool c1, bool c2, bool c3) {
    constexpr std::array<int, 3> none{4, 4, 4};
    if (c0 && c3) return {c1 ? std::array{0, 1, 3} : none, c2 ? std::array{0, 3, 2} : none};
    return {c0 && c1 && c2 ? std::array{0, 1, 2} : none, c1 && c2 && c3 ? std::array{1, 3, 2} : none};
}

} // namespace ff::ghosts
