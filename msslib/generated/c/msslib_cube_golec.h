// Generated from derivations/elements/cube_golec.py by `python -m derivations.codegen`. Do not edit.
// source-sha256: 2baf740924006b24ab708a6eb9fe0afe8cc5962c5c534f961faf5ee0c0b2c7f1
// body-sha256: 9784950811e66869507c2e6a5333a13597aaca22b37d7f281c7d155d98c39e9f
/* Cube with edge, face and inner springs and volume correction (Golec et al.), in C99 (units and linkage: msslib_api.h).
 * Printed from the expressions of msslib/generated/cube_golec.py (derivations/elements/cube_golec.py). */
#ifndef MSSLIB_CUBE_GOLEC_H
#define MSSLIB_CUBE_GOLEC_H

#include "msslib_api.h"

MSSLIB_BEGIN_DECLS

enum { MSSLIB_GOLEC_CUBE_K_EDGE, MSSLIB_GOLEC_CUBE_K_FACE, MSSLIB_GOLEC_CUBE_K_INNER, MSSLIB_GOLEC_CUBE_KAPPA, MSSLIB_GOLEC_CUBE_N_OUT };
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

enum { MSSLIB_GOLEC_CUBE_PUBLISHED_K_EDGE, MSSLIB_GOLEC_CUBE_PUBLISHED_K_FACE, MSSLIB_GOLEC_CUBE_PUBLISHED_K_INNER, MSSLIB_GOLEC_CUBE_PUBLISHED_KAPPA, MSSLIB_GOLEC_CUBE_PUBLISHED_N_OUT };
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

MSSLIB_END_DECLS

#endif /* MSSLIB_CUBE_GOLEC_H */
