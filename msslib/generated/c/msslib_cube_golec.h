// Generated from derivations/elements/cube_golec.py by `python -m derivations.codegen`. Do not edit.
// source-sha256: a8168c2ba54679e6402a4e966c218a01ad537a3264fab6bd8e4b3f7f596578f3
// body-sha256: 0d238d4fdc2f5bdb6dcaa28eebe4aa10cb54605177300b8e9a011a8f52bf3db9
/* Cube with edge, face and inner springs and volume correction (Golec et al.), in C99.
 *
 * Printed by SymPy's C99 printer from the expressions that msslib/generated/cube_golec.py is
 * printed from (derivations/elements/cube_golec.py), with the same common subexpressions;
 * `python -m derivations.codegen` writes both, do not edit. msslib_mss.h includes every module.
 * SI units: E in Pa, lengths in m, spring constants in N/m, energies in J, gradients in N,
 * Hessians in N/m (row-major, node by node: x0, y0(, z0), x1, ...).
 * Functions are `static inline` unless MSSLIB_API is defined before this header is
 * included (define it empty to compile them with external linkage, e.g. into a library).
 * Link with -lm. */
#ifndef MSSLIB_CUBE_GOLEC_H
#define MSSLIB_CUBE_GOLEC_H

#include <math.h>

#ifndef MSSLIB_API
#define MSSLIB_API static inline
#endif

#ifdef __cplusplus
extern "C" {
#endif

#define MSSLIB_GOLEC_CUBE_N_OUT 4
#define MSSLIB_GOLEC_CUBE_K_EDGE 0
#define MSSLIB_GOLEC_CUBE_K_FACE 1
#define MSSLIB_GOLEC_CUBE_K_INNER 2
#define MSSLIB_GOLEC_CUBE_KAPPA 3

/* golec_cube: Per-element constants of a cube of edge a (sum the edge springs over the up to 4 cubes sharing an edge, face diagonals over the up to 2 cubes sharing a face) and kappa [Pa] of the volume energy kappa/(2 V0) (V - V0)^2. The lattice reproduces the isotropic (lambda, mu) exactly.
 * Writes out[0..3] = (k_edge, k_face, k_inner, kappa). */
MSSLIB_API void msslib_golec_cube(double E, double nu, double a, double A, double *out)
{
    const double _c0 = 2*A;
    const double _c1 = E*a/(_c0*nu + _c0 + 3*nu + 3);
    const double _c2 = (3.0/4.0)*_c1;
    out[0] = (1.0/8.0)*_c1*(4*A + 3);
    out[1] = _c2;
    out[2] = A*_c2;
    out[3] = -1.0/2.0*E*(4*nu - 1)/(2*pow(nu, 2) + nu - 1);
}

#define MSSLIB_GOLEC_CUBE_PUBLISHED_N_OUT 4
#define MSSLIB_GOLEC_CUBE_PUBLISHED_K_EDGE 0
#define MSSLIB_GOLEC_CUBE_PUBLISHED_K_FACE 1
#define MSSLIB_GOLEC_CUBE_PUBLISHED_K_INNER 2
#define MSSLIB_GOLEC_CUBE_PUBLISHED_KAPPA 3

/* golec_cube_published: Golec et al.'s constants as printed (k_edge and k_face are the assembled values of an interior spring).
 * Writes out[0..3] = (k_edge, k_face, k_inner, kappa). */
MSSLIB_API void msslib_golec_cube_published(double E, double nu, double a, double A, double *out)
{
    const double _c0 = (6.0/5.0)*E*a/(4*A + 3);
    out[0] = _c0*((8.0/3.0)*A + 1);
    out[1] = _c0;
    out[2] = A*_c0;
    out[3] = -1.0/2.0*E*(4*nu - 1)/((nu + 1)*(2*nu - 1));
}

#ifdef __cplusplus
}
#endif

#endif /* MSSLIB_CUBE_GOLEC_H */
