// Generated from derivations/elements/tetrahedron.py by `python -m derivations.codegen`. Do not edit.
// source-sha256: 5bb62d6e7e2cb1f7e003dcfe035a9bb825e60f4b36a4cf6de13003e8a19891dd
// body-sha256: 738438200b0fb2aa500fae7fafe7d5ed17024c3591a585f1464bc59692366c65
/* Regular tetrahedron, least squares (Lloyd et al. eqs. 12-14), in C99 (units and linkage: msslib_api.h).
 * Printed from the expressions of msslib/generated/tetrahedron.py (derivations/elements/tetrahedron.py). */
#ifndef MSSLIB_TETRAHEDRON_H
#define MSSLIB_TETRAHEDRON_H

#include "msslib_api.h"

MSSLIB_BEGIN_DECLS

/* lloyd_tetrahedron: Per-element spring constant of a regular tetrahedron of edge l (least squares at nu = 1/4, eq. 12); use the equivalent edge length of eq. 13 for other shapes; sum over the tetrahedra sharing the edge.
 * Returns k. */
MSSLIB_API double msslib_lloyd_tetrahedron(double E, double l)
{
    return (2.0/25.0)*sqrt(2)*E*l;
}

/* lloyd_tetrahedron_general_nu: Least-squares spring constant for any nu (per element).
 * Returns k. */
MSSLIB_API double msslib_lloyd_tetrahedron_general_nu(double E, double nu, double l)
{
    return (1.0/15.0)*sqrt(2)*E*l*(nu - 1)/((nu + 1)*(2*nu - 1));
}

enum { MSSLIB_LLOYD_TETRAHEDRON_VOLUME_K, MSSLIB_LLOYD_TETRAHEDRON_VOLUME_K_VOLUME, MSSLIB_LLOYD_TETRAHEDRON_VOLUME_N_OUT };
/* lloyd_tetrahedron_volume: Per-element spring constant and volume-energy coefficient k_V of E_V = k_V/(2 V0^2)(V - V0)^2, least squares for any nu (eq. 14 is the case nu = 1/4).
 * Writes out[0..1] = (k, k_volume). */
MSSLIB_API void msslib_lloyd_tetrahedron_volume(double E, double nu, double l, double *out)
{
    const double _c0 = sqrt(2)*E/(nu + 1);
    out[0] = (2.0/21.0)*_c0*l;
    out[1] = -1.0/84.0*_c0*pow(l, 3)*(13*nu - 3)/(2*nu - 1);
}

/* equivalent_edge_length: Edge of the regular tetrahedron of volume V (eq. 13).
 * Returns l. */
MSSLIB_API double msslib_equivalent_edge_length(double V)
{
    return sqrt(2)*cbrt(3)*cbrt(V);
}

enum { MSSLIB_LLOYD_TETRAHEDRON_VOLUME_PUBLISHED_K, MSSLIB_LLOYD_TETRAHEDRON_VOLUME_PUBLISHED_K_VOLUME, MSSLIB_LLOYD_TETRAHEDRON_VOLUME_PUBLISHED_N_OUT };
/* lloyd_tetrahedron_volume_published: Lloyd et al.'s eq. 14 as printed (the optimum at nu = 1/4).
 * Writes out[0..1] = (k, k_volume). */
MSSLIB_API void msslib_lloyd_tetrahedron_volume_published(double E, double l, double *out)
{
    const double _c0 = sqrt(2)*E;
    out[0] = (8.0/105.0)*_c0*l;
    out[1] = (1.0/210.0)*_c0*pow(l, 3);
}

MSSLIB_END_DECLS

#endif /* MSSLIB_TETRAHEDRON_H */
