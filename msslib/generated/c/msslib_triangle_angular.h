// Generated from derivations/elements/triangle_angular.py by `python -m derivations.codegen`. Do not edit.
// source-sha256: 3f3e6594a47f17c23760017ea2dfd73e990a9e5823b3b48bb95a1ec61cefbda3
// body-sha256: 666ed28d996e4b629e2d25822fc536937149ffc24f310907ef001194ef6b2a72
/* Triangle of any shape with tensile and angular springs (Delingette 2008), in C99 (units and linkage: msslib_api.h).
 * Printed from the expressions of msslib/generated/triangle_angular.py (derivations/elements/triangle_angular.py). */
#ifndef MSSLIB_TRIANGLE_ANGULAR_H
#define MSSLIB_TRIANGLE_ANGULAR_H

#include "msslib_api.h"

MSSLIB_BEGIN_DECLS

enum { MSSLIB_DELINGETTE_TRIANGLE_K_01, MSSLIB_DELINGETTE_TRIANGLE_K_12, MSSLIB_DELINGETTE_TRIANGLE_K_02, MSSLIB_DELINGETTE_TRIANGLE_C_01_12, MSSLIB_DELINGETTE_TRIANGLE_C_12_02, MSSLIB_DELINGETTE_TRIANGLE_C_01_02, MSSLIB_DELINGETTE_TRIANGLE_N_OUT };
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

MSSLIB_END_DECLS

#endif /* MSSLIB_TRIANGLE_ANGULAR_H */
