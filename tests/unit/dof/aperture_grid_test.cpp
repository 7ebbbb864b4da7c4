// Tests of the aperture drawn on a tap grid (dof/aperture_grid.h): mass, symmetry, orientation
// on both sides of the focal plane, bad input.
#include <dof/aperture_grid.h>

#include <gtest/gtest.h>

#include <cmath>

namespace focal::test {
namespace {

double sum(const dof::ApertureGrid& g) {
    double s = 0.0;
    for (float w : g.weight)
        s += double(w);
    return s;
}

TEST(ApertureGrid, CircleIsTheSameOnBothSidesAndRound) {
    raster::Result<dof::ApertureGrid> far = dof::apertureGrid({}, 6, dof::FocalSide::Far);
    raster::Result<dof::ApertureGrid> near = dof::apertureGrid({}, 6, dof::FocalSide::Near);
    ASSERT_TRUE(far.ok() && near.ok());
    EXPECT_NEAR(sum(*far), 1.0, 1e-6);
    EXPECT_TRUE(dof::sameWeights(*far, *near));  // symmetric under a half turn, bit for bit
    EXPECT_NEAR(far->second_moment, 0.25, 1e-3); // the uniform disk
    // A corner cell, [2/3, 1]^2 of the lens square, meets the unit disk in a sliver of area
    // ~0.0033 (share ~0.001); a centre cell lies inside it: share (1/3)^2 / pi ~ 0.035.
    EXPECT_GT(far->at(0, 0), 0.0f);
    EXPECT_LT(far->at(0, 0), 0.002f);
    EXPECT_NEAR(far->at(2, 2), 1.0 / (9.0 * M_PI), 0.002);
    // Mirror symmetric up to sampling noise.
    for (uint32_t b = 0; b < 6; ++b)
        for (uint32_t a = 0; a < 6; ++a)
            EXPECT_NEAR(far->at(a, b), far->at(5 - a, b), 5e-4) << a << "," << b;
}

TEST(ApertureGrid, TriangleTurnsInFrontOfTheFocalPlane) {
    // A triangle with a vertex up (+y on the lens). Behind the focal plane the gather reads
    // image offset R(-v.x, +v.y): the vertex's mass sits in the bottom image row (y down);
    // in front of it the grid is turned by 180 degrees.
    dof::ApertureShape triangle;
    triangle.kind = dof::ApertureKind::Polygon;
    triangle.blades = 3;
    raster::Result<dof::ApertureGrid> far = dof::apertureGrid(triangle, 4, dof::FocalSide::Far);
    raster::Result<dof::ApertureGrid> near = dof::apertureGrid(triangle, 4, dof::FocalSide::Near);
    ASSERT_TRUE(far.ok() && near.ok());
    EXPECT_NEAR(sum(*far), 1.0, 1e-6);
    EXPECT_FALSE(dof::sameWeights(*far, *near));
    for (uint32_t b = 0; b < 4; ++b)
        for (uint32_t a = 0; a < 4; ++a)
            EXPECT_EQ(near->at(a, b), far->at(3 - a, 3 - b));
    // The vertex (lens y = 1) is a narrow tip, the base (lens y = -1/2) a wide edge: the row
    // near the base holds more than the row near the tip. Far side: the tip's row is the
    // bottom one (b = 3), the base's the top one's neighbour (b = 1, lens y in [0, -1/2]).
    auto row = [](const dof::ApertureGrid& g, uint32_t b) {
        double r = 0.0;
        for (uint32_t a = 0; a < g.size; ++a)
            r += double(g.at(a, b));
        return r;
    };
    EXPECT_GT(row(*far, 1), 2.0 * row(*far, 3));
    EXPECT_NEAR(row(*far, 0), 0.0, 1e-6); // nothing below the base at lens y = -1/2
    EXPECT_GT(row(*near, 2), 2.0 * row(*near, 0));
}

TEST(ApertureGrid, TriangleOnItsSideMirrorsInXBehindTheFocalPlane) {
    // Turned by 90 degrees the triangle's tip points to lens -x and its base stands at lens
    // x = +1/2. Behind the focal plane the gather reads image offset -v.x: the tip's mass sits in
    // the right column (a = 3), the base's in column 1, and column 0 (lens x > 1/2) is empty.
    dof::ApertureShape triangle;
    triangle.kind = dof::ApertureKind::Polygon;
    triangle.blades = 3;
    triangle.rotation_deg = 90.0f;
    raster::Result<dof::ApertureGrid> far = dof::apertureGrid(triangle, 4, dof::FocalSide::Far);
    ASSERT_TRUE(far.ok());
    auto column = [&](uint32_t a) {
        double c = 0.0;
        for (uint32_t b = 0; b < 4; ++b)
            c += double(far->at(a, b));
        return c;
    };
    EXPECT_NEAR(column(0), 0.0, 1e-6);
    EXPECT_GT(column(1), 2.0 * column(3));
    EXPECT_GT(column(3), 0.0);
}

TEST(ApertureGrid, BadInputIsAnError) {
    EXPECT_FALSE(dof::apertureGrid({}, 0, dof::FocalSide::Far).ok());
    EXPECT_FALSE(dof::apertureGrid({}, 65, dof::FocalSide::Far).ok());
    dof::ApertureShape two_blades;
    two_blades.kind = dof::ApertureKind::Polygon;
    two_blades.blades = 2;
    EXPECT_FALSE(dof::apertureGrid(two_blades, 4, dof::FocalSide::Far).ok());
}

} // namespace
} // namespace focal::test
