// Generated from derivations/elements/tetrahedron.py by `python -m derivations.codegen`. Do not edit.
// source-sha256: 0d0bf17a5dedd15988d2fb7803022fbcfe60cfc94439390d158472ccb5d53756
// body-sha256: f939343cb2baf0fb848f36b70ff7f3b1f31ba015f97cabe173307781e3e06e1c
/* Regular tetrahedron, least squares (Lloyd et al. eqs. 12-14), in C99.
 *
 * Printed by SymPy's C99 printer from the expressions that msslib/generated/tetrahedron.py is
 * printed from (derivations/elements/tetrahedron.py), with the same common subexpressions;
 * `python -m derivations.codegen` writes both, do not edit. msslib_mss.h includes every module.
 * SI units: E in Pa, lengths in m, spring constants in N/m, energies in J, gradients in N,
 * Hessians in N/m (row-major, node by node: x0, y0(, z0), x1, ...).
 * Functions are `static inline` unless MSSLIB_API is defined before this header is
 * included (define it empty to compile them with external linkage, e.g. into a library).
 * Link with -lm. */
#ifndef MSSLIB_TETRAHEDRON_H
#define MSSLIB_TETRAHEDRON_H

#include <math.h>

#ifndef MSSLIB_API
#define MSSLIB_API static inline
#endif

#ifdef __cplusplus
extern "C" {
#endif

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

#define MSSLIB_LLOYD_TETRAHEDRON_VOLUME_N_OUT 2
#define MSSLIB_LLOYD_TETRAHEDRON_VOLUME_K 0
#define MSSLIB_LLOYD_TETRAHEDRON_VOLUME_K_VOLUME 1

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

#define MSSLIB_LLOYD_TETRAHEDRON_VOLUME_PUBLISHED_N_OUT 2
#define MSSLIB_LLOYD_TETRAHEDRON_VOLUME_PUBLISHED_K 0
#define MSSLIB_LLOYD_TETRAHEDRON_VOLUME_PUBLISHED_K_VOLUME 1

/* lloyd_tetrahedron_volume_published: Lloyd et al.'s eq. 14 as printed (the optimum at nu = 1/4).
 * Writes out[0..1] = (k, k_volume). */
MSSLIB_API void msslib_lloyd_tetrahedron_volume_published(double E, double l, double *out)
{
    const double _c0 = sqrt(2)*E;
    out[0] = (8.0/105.0)*_c0*l;
    out[1] = (1.0/210.0)*_c0*pow(l, 3);
}

#ifdef __cplusplus
}
#endif

#endif /* MSSLIB_TETRAHEDRON_H */
