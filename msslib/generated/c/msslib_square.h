// Generated from derivations/elements/square.py by `python -m derivations.codegen`. Do not edit.
// source-sha256: 9804f2206eea30d6e805ab4abac0719d5f3426bc3efb00253187c092359974e1
// body-sha256: 1cf15a42ad791d67268aa990ddd04a24b07e3e4ce60a7621e6acedc466da7f91
/* Square with prestrained springs, plane stress (Lloyd et al. eqs. 10-11), in C99 (units and linkage: msslib_api.h).
 * Printed from the expressions of msslib/generated/square.py (derivations/elements/square.py). */
#ifndef MSSLIB_SQUARE_H
#define MSSLIB_SQUARE_H

#include "msslib_api.h"

MSSLIB_BEGIN_DECLS

enum { MSSLIB_LLOYD_SQUARE_K_EDGE, MSSLIB_LLOYD_SQUARE_K_DIAGONAL, MSSLIB_LLOYD_SQUARE_REST_FACTOR_EDGE, MSSLIB_LLOYD_SQUARE_REST_FACTOR_DIAGONAL, MSSLIB_LLOYD_SQUARE_N_OUT };
/* lloyd_square: Per-element constants of the square: edge springs (sum over the squares sharing the edge) and diagonal springs, with rest length = factor x rest distance. Exact for nu = 1/3.
 * Writes out[0..3] = (k_edge, k_diagonal, rest_factor_edge, rest_factor_diagonal). */
MSSLIB_API void msslib_lloyd_square(double E, double t, double *out)
{
    const double _c0 = E*t;
    out[0] = (5.0/16.0)*_c0;
    out[1] = (7.0/16.0)*_c0;
    out[2] = 6.0/5.0;
    out[3] = 6.0/7.0;
}

MSSLIB_END_DECLS

#endif /* MSSLIB_SQUARE_H */
