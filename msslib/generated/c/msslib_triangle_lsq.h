// Generated from derivations/elements/triangle_lsq.py by `python -m derivations.codegen`. Do not edit.
// source-sha256: ff8a051dcdda6c6edcadb1b42336594c8aa81007b02247f1f63582cd22d3de6a
// body-sha256: c170b5b8e3023be5ac195a0759f71c4844255dea36ed3e84d56a659f5840c7b2
/* Triangle of any shape, three springs fitted to its own CST by least squares (Natsupakpong and Cavusoglu 2010, closed form), in C99 (units and linkage: msslib_api.h).
 * Printed from the expressions of msslib/generated/triangle_lsq.py (derivations/elements/triangle_lsq.py). */
#ifndef MSSLIB_TRIANGLE_LSQ_H
#define MSSLIB_TRIANGLE_LSQ_H

#include "msslib_api.h"

MSSLIB_BEGIN_DECLS

enum { MSSLIB_LSQ_TRIANGLE_K_01, MSSLIB_LSQ_TRIANGLE_K_12, MSSLIB_LSQ_TRIANGLE_K_02, MSSLIB_LSQ_TRIANGLE_N_OUT };
/* lsq_triangle: Spring constants k_ij (edge i-j, N/m) of one triangle with nodes (0, 0), (a, 0), (x2, y2), y2 > 0, minimising the Frobenius distance of the springs' stiffness at rest from the triangle's own plane-stress CST (thickness t); per element (sum over the triangles sharing an edge). Exact only on the equilateral triangle at nu = 1/3; can be negative for obtuse triangles.
 * Writes out[0..2] = (k_01, k_12, k_02). */
MSSLIB_API void msslib_lsq_triangle(double E, double nu, double t, double a, double x2, double y2, double *out)
{
    const double _c0 = a*x2;
    const double _c1 = 16*_c0;
    const double _c2 = pow(a, 2);
    const double _c3 = pow(x2, 2);
    const double _c4 = pow(y2, 2);
    const double _c5 = 4*_c2;
    const double _c6 = _c5*nu;
    const double _c7 = 16*_c3;
    const double _c8 = 4*_c0;
    const double _c9 = 4*_c3;
    const double _c10 = 8*_c4;
    const double _c11 = _c2*nu;
    const double _c12 = _c10 - _c11 + _c2 + _c8*nu - _c8 - _c9*nu + _c9;
    const double _c13 = _c3 + _c4;
    const double _c14 = -2*_c0 + _c13 + _c2;
    const double _c15 = pow(_c14, -2);
    const double _c16 = -_c0 + _c13;
    const double _c17 = _c15*pow(_c16, 4);
    const double _c18 = pow(_c13, -2);
    const double _c19 = (1.0/4.0)*_c18;
    const double _c20 = pow(x2, 3);
    const double _c21 = _c20*a;
    const double _c22 = 4*_c21;
    const double _c23 = _c4*_c8;
    const double _c24 = pow(x2, 4);
    const double _c25 = pow(y2, 4);
    const double _c26 = _c24*nu;
    const double _c27 = _c25*nu;
    const double _c28 = 2*_c3;
    const double _c29 = _c28*_c4;
    const double _c30 = _c24 + _c25 - _c26 - _c27 - _c29*nu + _c29;
    const double _c31 = _c10*_c2 + _c22*nu - _c22 + _c23*nu - _c23 + _c3*_c5 - _c3*_c6 + _c30;
    const double _c32 = _c18*_c31;
    const double _c33 = _c3*_c32;
    const double _c34 = a - x2;
    const double _c35 = pow(_c34, 2);
    const double _c36 = pow(a, 4);
    const double _c37 = _c36*nu;
    const double _c38 = _c2*_c4;
    const double _c39 = _c11*_c28 + 2*_c11*_c4 - _c2*_c28 + _c30 + _c36 - _c37 + 6*_c38;
    const double _c40 = _c15*_c39;
    const double _c41 = pow(_c16, 2);
    const double _c42 = 2*_c18;
    const double _c43 = _c15*pow(_c34, 4);
    const double _c44 = (1.0/2.0)*E*t/(a*y2*(nu - 1)*(nu + 1)*(-_c15*_c18*_c3*_c35*_c41 + _c17*_c42 + _c24*_c42 + 2*_c43 - 32));
    const double _c45 = 4*_c26;
    const double _c46 = 4*_c27;
    const double _c47 = 8*_c3;
    const double _c48 = _c10*_c3;
    const double _c49 = _c48*nu;
    const double _c50 = _c12*_c3;
    out[0] = _c44*(-_c1 - _c12*_c17*_c19 + (1.0/4.0)*_c15*_c18*_c3*_c39*_c41 + (1.0/4.0)*_c15*_c18*_c31*_c35*_c41 + 4*_c2 + 16*_c3 - _c33 - _c35*_c40 + 32*_c4 - _c6 - _c7*nu + 16*a*nu*x2);
    out[1] = _c44*(_c10*_c11 + _c11*_c47 - _c12*_c35 - _c19*_c24*_c39 + _c19*_c41*_c50 - _c2*_c47 + 4*_c24 + 4*_c25 - _c32*_c41 + (1.0/4.0)*_c33*_c35 + 4*_c36 - 4*_c37 + 24*_c38 - _c45 - _c46 + _c48 - _c49)/_c14;
    out[2] = _c44*(-_c1*_c4 - _c11*_c7 + (1.0/4.0)*_c12*_c15*_c35*_c41 + (1.0/4.0)*_c15*_c3*_c35*_c39 + 16*_c2*_c3 + 32*_c2*_c4 + 16*_c20*a*nu - 16*_c21 + 4*_c24 + 4*_c25 + 8*_c3*_c4 - 1.0/4.0*_c31*_c43 + 16*_c4*a*nu*x2 - _c40*_c41 - _c45 - _c46 - _c49 - _c50)/_c13;
}

MSSLIB_END_DECLS

#endif /* MSSLIB_TRIANGLE_LSQ_H */
