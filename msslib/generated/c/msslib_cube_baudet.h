// Generated from derivations/elements/cube_baudet.py by `python -m derivations.codegen`. Do not edit.
// source-sha256: ac1f20ec5c9c2b68e2bc8dd50a348a865f52c829e68dab20a752ba1bd5d03c96
// body-sha256: 8eb43134e8defdcfc71620e0b36abf3ee01571da8e2e61098deb73291c8a5405
/* Cube with edge and inner-diagonal springs and orthogonal correction (Baudet et al.), in C99.
 *
 * Printed by SymPy's C99 printer from the expressions that msslib/generated/cube_baudet.py is
 * printed from (derivations/elements/cube_baudet.py), with the same common subexpressions;
 * `python -m derivations.codegen` writes both, do not edit. msslib_mss.h includes every module.
 * SI units: E in Pa, lengths in m, spring constants in N/m, energies in J, gradients in N,
 * Hessians in N/m (row-major, node by node: x0, y0(, z0), x1, ...).
 * Functions are `static inline` unless MSSLIB_API is defined before this header is
 * included (define it empty to compile them with external linkage, e.g. into a library).
 * Link with -lm. */
#ifndef MSSLIB_CUBE_BAUDET_H
#define MSSLIB_CUBE_BAUDET_H

#include <math.h>

#ifndef MSSLIB_API
#define MSSLIB_API static inline
#endif

#ifdef __cplusplus
extern "C" {
#endif

#define MSSLIB_BAUDET_CUBE_N_OUT 3
#define MSSLIB_BAUDET_CUBE_K_EDGE 0
#define MSSLIB_BAUDET_CUBE_K_DIAGONAL 1
#define MSSLIB_BAUDET_CUBE_CORRECTION_FACTOR 2

/* baudet_cube: Per-element constants of a cube of edge a: edge springs (sum over the cubes sharing the edge), inner diagonals, and the factor c of the correction force F_perp = c F_i applied, as a total per face, on each face orthogonal to the elongation force F_i (Baudet eqs. 7-8).
 * Writes out[0..2] = (k_edge, k_diagonal, correction_factor). */
MSSLIB_API void msslib_baudet_cube(double E, double nu, double a, double *out)
{
    const double _c0 = E*a/(nu + 1);
    out[0] = (1.0/8.0)*_c0*(4*nu + 1);
    out[1] = (3.0/8.0)*_c0;
    out[2] = 1.0/2.0 - 2*nu;
}

#define MSSLIB_BAUDET_CUBE_PUBLISHED_N_OUT 3
#define MSSLIB_BAUDET_CUBE_PUBLISHED_K_EDGE 0
#define MSSLIB_BAUDET_CUBE_PUBLISHED_K_DIAGONAL 1
#define MSSLIB_BAUDET_CUBE_PUBLISHED_CORRECTION_FACTOR 2

/* baudet_cube_published: Baudet et al.'s eqs. 7-8 as printed (correction factor -(4 nu - 1)/16).
 * Writes out[0..2] = (k_edge, k_diagonal, correction_factor). */
MSSLIB_API void msslib_baudet_cube_published(double E, double nu, double a, double *out)
{
    const double _c0 = 4*nu;
    const double _c1 = E*a/(nu + 1);
    out[0] = (1.0/8.0)*_c1*(_c0 + 1);
    out[1] = (3.0/8.0)*_c1;
    out[2] = 1.0/16.0 - 1.0/16.0*_c0;
}

#ifdef __cplusplus
}
#endif

#endif /* MSSLIB_CUBE_BAUDET_H */
