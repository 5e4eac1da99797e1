// Generated from derivations/elements/triangle.py by `python -m derivations.codegen`. Do not edit.
// source-sha256: 0d9f220e94ad8c1b2208895a0c09a40ffc8c3fa8c40bfea289537f12f5c48f4e
// body-sha256: d6dd0ef1e5e4fdf007262366fb37c4bb4ff2fd80c599af2d0de2dd1b6fca4599
/* Equilateral triangle, plane stress (Lloyd et al. eq. 8; van Gelder, eq. 9), in C99 (units and linkage: msslib_api.h).
 * Printed from the expressions of msslib/generated/triangle.py (derivations/elements/triangle.py). */
#ifndef MSSLIB_TRIANGLE_H
#define MSSLIB_TRIANGLE_H

#include "msslib_api.h"

MSSLIB_BEGIN_DECLS

/* lloyd_triangle: Spring constant of each edge of an equilateral triangle, per element (sum over the triangles sharing the edge). Exact for nu = 1/3.
 * Returns k. */
MSSLIB_API double msslib_lloyd_triangle(double E, double t)
{
    return (1.0/4.0)*sqrt(3)*E*t;
}

/* van_gelder_triangle: Van Gelder's spring constant, per element: E t A_e / l^2.
 * Returns k. */
MSSLIB_API double msslib_van_gelder_triangle(double E, double t, double A_e, double l)
{
    return A_e*E*t/pow(l, 2);
}

MSSLIB_END_DECLS

#endif /* MSSLIB_TRIANGLE_H */
