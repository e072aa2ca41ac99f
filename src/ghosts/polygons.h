#pragma once
// Clipped polygons of uniform or linear density: one ghost instance at one wavelength as the shaped renderer
// draws it (shaped_ghosts.h) and as its fits are measured (ghost_fit.h).

#include <glm/vec2.hpp>

#include <cstddef>
#include <cstdint>
#include <vector>

namespace ff::ghosts {

struct ShapedPolygons {
    struct Poly {
        std::uint32_t first = 0, count = 0; ///< its vertices: vertices[first .. first + count), in order
        float yMin = 0.0f, yMax = 0.0f;     ///< rows it spans, pixels
        double energy = 0.0;                ///< flux spread over it
    };
    std::vector<glm::vec2> vertices; ///< pixels of the frame drawn into (origin top-left, centres at +0.5)
    std::vector<Poly> polys;
    /// Per polygon, its density's gradient relative to its mean, per pixel: (energy / area)
    /// (1 + g . (p - c)) about its centroid c (trace::CoverageRaster::polygon); empty while every
    /// polygon is uniform (gradient(i) then reads 0).
    std::vector<glm::vec2> gradients;
    double energy = 0.0; ///< drawn, in and out of the frame
    std::size_t triangles = 0;
    double pupilCells = 0.0; ///< the lit pupil area the polygons come from, in cells of their mesh
    /// The polygons' areas summed, in pixels of their frame: the pixels they cover, a region the
    /// ghost's map folds over counted once per sheet.
    double areaPx = 0.0;

    void add(const glm::dvec2* p, std::size_t n, double e, const glm::dvec2& gradient = glm::dvec2(0.0));
    glm::dvec2 gradient(std::size_t i) const { return gradients.empty() ? glm::dvec2(0.0) : glm::dvec2(gradients[i]); }
};

} // namespace ff::ghosts
