#pragma once
// The iris: a regular N-blade polygon (or a circle when blades = 0) in the stop's vertex plane.
// Its opening has the area of the circle of the working stop radius r (so the f-number's light
// gathering is unchanged): circumradius R = r sqrt(2 pi / (N sin(2 pi / N))). Blade edges are straight;
// rotation turns the first vertex away from +x, counter-clockwise.

namespace ff::trace {

struct Iris {
    int blades = 0; ///< 0 = circular
    double rotationRad = 0.0;
    double radius = 0.0; ///< working stop radius (equivalent circle), mm
    double circumradius = 0.0;

    Iris() = default;
    Iris(int blades, double rotationRad, double radius);

    /// True when (x, y), mm from the axis in the stop plane, lies inside the opening.
    bool contains(double x, double y) const;
    /// How far (x, y) lies inside the opening, mm: the distance to the nearest blade's edge line (the
    /// circle for a circular iris), negative outside; contains() is margin() >= 0 up to rounding.
    double margin(double x, double y) const;
    /// True when the opening is its own mirror image across the line through the axis at angle
    /// lineRad from +x: always for a circle; for a polygon, on the lines through its vertices and
    /// through its edges' midpoints (rotation + k pi / blades).
    bool mirrorSymmetricAbout(double lineRad) const;
};

} // namespace ff::trace
