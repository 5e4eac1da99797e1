// Generated from derivations/elements/cube_baudet.py by `python -m derivations.codegen`. Do not edit.
// source-sha256: 805c5add68aa437da1e97b29747d7bdd7abf33d152a3c10f7f10b91873681ac4
// body-sha256: ed3871ac34bc05ede2d93d77dc6bfa5d5cf9d38e7fe0c566cea46cd9da016706
/* Cube with edge and inner-diagonal springs and orthogonal correction (Baudet et al.), in C99 (units and linkage: msslib_api.h).
 * Printed from the expressions of msslib/generated/cube_baudet.py (derivations/elements/cube_baudet.py). */
#ifndef MSSLIB_CUBE_BAUDET_H
#define MSSLIB_CUBE_BAUDET_H

#include "msslib_api.h"

MSSLIB_BEGIN_DECLS

enum { MSSLIB_BAUDET_CUBE_K_EDGE, MSSLIB_BAUDET_CUBE_K_DIAGONAL, MSSLIB_BAUDET_CUBE_CORRECTION_FACTOR, MSSLIB_BAUDET_CUBE_N_OUT };
/* baudet_cube: Per-element constants of a cube of edge a: edge springs (sum over the cubes sharing the edge), inner diagonals, and the factor c of the correction force F_perp = c F_i applied, as a total per face, on each face orthogonal to the elongation force F_i (Baudet eqs. 7-8).
 * Writes out[0..2] = (k_edge, k_diagonal, correction_factor). */
MSSLIB_API void msslib_baudet_cube(double E, double nu, double a, double *out)
{
    const double _c0 = E*a/(nu + 1);
    out[0] = (1.0/8.0)*_c0*(4*nu + 1);
    out[1] = (3.0/8.0)*_c0;
    out[2] = 1.0/2.0 - 2*nu;
}

enum { MSSLIB_BAUDET_CUBE_PUBLISHED_K_EDGE, MSSLIB_BAUDET_CUBE_PUBLISHED_K_DIAGONAL, MSSLIB_BAUDET_CUBE_PUBLISHED_CORRECTION_FACTOR, MSSLIB_BAUDET_CUBE_PUBLISHED_N_OUT };
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

MSSLIB_END_DECLS

#endif /* MSSLIB_CUBE_BAUDET_H */
