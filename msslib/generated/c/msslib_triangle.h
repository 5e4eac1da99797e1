// Generated from derivations/elements/triangle.py by `python -m derivations.codegen`. Do not edit.
// source-sha256: 99a127095acd37fc49dab13ca59f00408cd1a1fb9e96269716115758fe0325f8
// body-sha256: 298fe9aba68a9c879d57af4b9e347fdcc7e03f133b5f7ce26b984974550d7fa7
/* Equilateral triangle, plane stress (Lloyd et al. eq. 8; van Gelder, eq. 9), in C99.
 *
 * Printed by SymPy's C99 printer from the expressions that msslib/generated/triangle.py is
 * printed from (derivations/elements/triangle.py), with the same common subexpressions;
 * `python -m derivations.codegen` writes both, do not edit. msslib_mss.h includes every module.
 * SI units: E in Pa, lengths in m, spring constants in N/m, energies in J, gradients in N,
 * Hessians in N/m (row-major, node by node: x0, y0(, z0), x1, ...).
 * Functions are `static inline` unless MSSLIB_API is defined before this header is
 * included (define it empty to compile them with external linkage, e.g. into a library).
 * Link with -lm. */
#ifndef MSSLIB_TRIANGLE_H
#define MSSLIB_TRIANGLE_H

#include <math.h>

#ifndef MSSLIB_API
#define MSSLIB_API static inline
#endif

#ifdef __cplusplus
extern "C" {
#endif

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

#ifdef __cplusplus
}
#endif

#endif /* MSSLIB_TRIANGLE_H */
