// Generated from derivations/elements/square.py by `python -m derivations.codegen`. Do not edit.
// source-sha256: d3e9b7a12a70eebb3b75f7b0d21c74951422103b5fe4baf76f8c65382883ab7b
// body-sha256: 13b5965d96604f6d2aac3e0b15b3fde5c77ce864e6397a964dba8cab8b65bb35
/* Square with prestrained springs, plane stress (Lloyd et al. eqs. 10-11), in C99.
 *
 * Printed by SymPy's C99 printer from the expressions that msslib/generated/square.py is
 * printed from (derivations/elements/square.py), with the same common subexpressions;
 * `python -m derivations.codegen` writes both, do not edit. msslib_mss.h includes every module.
 * SI units: E in Pa, lengths in m, spring constants in N/m, energies in J, gradients in N,
 * Hessians in N/m (row-major, node by node: x0, y0(, z0), x1, ...).
 * Functions are `static inline` unless MSSLIB_API is defined before this header is
 * included (define it empty to compile them with external linkage, e.g. into a library).
 * Link with -lm. */
#ifndef MSSLIB_SQUARE_H
#define MSSLIB_SQUARE_H

#include <math.h>

#ifndef MSSLIB_API
#define MSSLIB_API static inline
#endif

#ifdef __cplusplus
extern "C" {
#endif

#define MSSLIB_LLOYD_SQUARE_N_OUT 4
#define MSSLIB_LLOYD_SQUARE_K_EDGE 0
#define MSSLIB_LLOYD_SQUARE_K_DIAGONAL 1
#define MSSLIB_LLOYD_SQUARE_REST_FACTOR_EDGE 2
#define MSSLIB_LLOYD_SQUARE_REST_FACTOR_DIAGONAL 3

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

#ifdef __cplusplus
}
#endif

#endif /* MSSLIB_SQUARE_H */
