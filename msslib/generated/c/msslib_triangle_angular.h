// Generated from derivations/elements/triangle_angular.py by `python -m derivations.codegen`. Do not edit.
// source-sha256: 028cdae218534b2e6b905926b730ef2e0cd489150f189af38537e219ceab17f7
// body-sha256: 583ea8afd0e0bd59467064df7fbe46947c5f4338aa4aae4dc80fbea0fd406a49
/* Triangle of any shape with tensile and angular springs (Delingette 2008), in C99.
 *
 * Printed by SymPy's C99 printer from the expressions that msslib/generated/triangle_angular.py is
 * printed from (derivations/elements/triangle_angular.py), with the same common subexpressions;
 * `python -m derivations.codegen` writes both, do not edit. msslib_mss.h includes every module.
 * SI units: E in Pa, lengths in m, spring constants in N/m, energies in J, gradients in N,
 * Hessians in N/m (row-major, node by node: x0, y0(, z0), x1, ...).
 * Functions are `static inline` unless MSSLIB_API is defined before this header is
 * included (define it empty to compile them with external linkage, e.g. into a library).
 * Link with -lm. */
#ifndef MSSLIB_TRIANGLE_ANGULAR_H
#define MSSLIB_TRIANGLE_ANGULAR_H

#include <math.h>

#ifndef MSSLIB_API
#define MSSLIB_API static inline
#endif

#ifdef __cplusplus
extern "C" {
#endif

#define MSSLIB_DELINGETTE_TRIANGLE_N_OUT 6
#define MSSLIB_DELINGETTE_TRIANGLE_K_01 0
#define MSSLIB_DELINGETTE_TRIANGLE_K_12 1
#define MSSLIB_DELINGETTE_TRIANGLE_K_02 2
#define MSSLIB_DELINGETTE_TRIANGLE_C_01_12 3
#define MSSLIB_DELINGETTE_TRIANGLE_C_12_02 4
#define MSSLIB_DELINGETTE_TRIANGLE_C_01_02 5

/* delingette_triangle: Tensile constants k_ij (edge i-j) and angular constants c_ij_pq (edges i-j and p-q) of one triangle with nodes (0, 0), (a, 0), (x2, y2), y2 > 0, in the energy sum k/4 D^2 + sum c/2 D D (D = l^2 - L^2, squared lengths). Exact against the CST for every triangle and nu.
 * Writes out[0..5] = (k_01, k_12, k_02, c_01_12, c_12_02, c_01_02). */
MSSLIB_API void msslib_delingette_triangle(double E, double nu, double t, double a, double x2, double y2, double *out)
{
    const double _c0 = pow(x2, 3);
    const double _c1 = 4*a;
    const double _c2 = pow(a, 2);
    const double _c3 = pow(y2, 2);
    const double _c4 = _c2*_c3;
    const double _c5 = _c3*a;
    const double _c6 = pow(x2, 2);
    const double _c7 = 2*_c6;
    const double _c8 = (1.0/8.0)*E*t/(pow(y2, 3)*(nu - 1)*(nu + 1));
    const double _c9 = _c3*nu;
    const double _c10 = _c3 + _c7 - _c9;
    const double _c11 = _c8/a;
    const double _c12 = 2*_c2;
    const double _c13 = _c9*a;
    const double _c14 = 2*x2;
    const double _c15 = 2*_c0 + _c14*_c3 - _c5;
    const double _c16 = _c8/_c2;
    out[0] = -_c8*(-_c0*_c1 + _c2*_c7 + 4*_c3*_c6 - _c4*nu + _c4 - 4*_c5*x2 + 2*pow(x2, 4) + 2*pow(y2, 4))/pow(a, 3);
    out[1] = -_c10*_c11;
    out[2] = -_c11*(-_c1*x2 + _c10 + _c12);
    out[3] = -_c16*(_c13 + _c15 - _c7*a);
    out[4] = -_c11*(_c14*a - _c3 - _c7 + _c9);
    out[5] = _c16*(-_c1*_c6 + _c12*x2 - _c13 + _c15);
}

#ifdef __cplusplus
}
#endif

#endif /* MSSLIB_TRIANGLE_ANGULAR_H */
