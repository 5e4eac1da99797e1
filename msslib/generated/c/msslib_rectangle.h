// Generated from derivations/elements/rectangle.py by `python -m derivations.codegen`. Do not edit.
// source-sha256: e92947b5ec9d5de17ea0a6e1b85c5c02f45582c90490a75e958fed379a5743ba
// body-sha256: 7164229a583f900ca146aca36a9edbb85c829bd260ee9c182fd4b8ef478eb2c2
/* Rectangle of aspect ratio r, plane stress, six prestrained springs (generalising Lloyd et al. Sec. 4.1), in C99 (units and linkage: msslib_api.h).
 * Printed from the expressions of msslib/generated/rectangle.py (derivations/elements/rectangle.py). */
#ifndef MSSLIB_RECTANGLE_H
#define MSSLIB_RECTANGLE_H

#include "msslib_api.h"

MSSLIB_BEGIN_DECLS

enum { MSSLIB_RECTANGLE_LEAST_SQUARES_K_H, MSSLIB_RECTANGLE_LEAST_SQUARES_K_V, MSSLIB_RECTANGLE_LEAST_SQUARES_K_D, MSSLIB_RECTANGLE_LEAST_SQUARES_C_H, MSSLIB_RECTANGLE_LEAST_SQUARES_C_V, MSSLIB_RECTANGLE_LEAST_SQUARES_C_D, MSSLIB_RECTANGLE_LEAST_SQUARES_N_OUT };
/* rectangle_least_squares: Least-squares springs of an a x b rectangle (r = b/a), plane stress, nu = 1/3, per element: k_h (the 2 edges along x, length a), k_v (the 2 edges along y, length b = r a), k_d (the 2 diagonals) and rest-length factors c_h, c_v, c_d (rest length = c times the rest distance). Edge constants add up over the elements sharing the edge. Exact only for r = 1 (Lloyd's 5/16, 7/16 E t; 6/5, 6/7); k and c are positive only for 0.4920 < r < 2.0324, and for r != 1 the element is NOT in equilibrium at rest (see rectangle_least_squares_equilibrium).
 * Writes out[0..5] = (k_h, k_v, k_d, c_h, c_v, c_d). */
MSSLIB_API void msslib_rectangle_least_squares(double E, double t, double r, double *out)
{
    const double _c0 = pow(r, 2);
    const double _c1 = pow(r, 4);
    const double _c2 = pow(r, 6);
    const double _c3 = -3*_c0 + 28*_c1 + 6*_c2 - 1;
    const double _c4 = _c1 + 1;
    const double _c5 = (1.0/16.0)*E*t/(r*(4*_c0 + _c4));
    const double _c6 = -28*_c0 + 3*_c1 + _c2 - 6;
    const double _c7 = _c0 + 1;
    const double _c8 = 19*_c0 + _c4;
    const double _c9 = 3*r;
    out[0] = _c3*_c5;
    out[1] = -_c5*_c6;
    out[2] = _c5*_c7*_c8;
    out[3] = 2*(14*_c1 + 2*_c2 + _c7)/_c3;
    out[4] = -2*(14*_c0 + _c1 + _c2 + 2)/_c6;
    out[5] = 2*(-_c0 + _c9 + 1)*(_c0 + _c9 - 1)/_c8;
}

enum { MSSLIB_RECTANGLE_LEAST_SQUARES_EQUILIBRIUM_K_H, MSSLIB_RECTANGLE_LEAST_SQUARES_EQUILIBRIUM_K_V, MSSLIB_RECTANGLE_LEAST_SQUARES_EQUILIBRIUM_K_D, MSSLIB_RECTANGLE_LEAST_SQUARES_EQUILIBRIUM_C_H, MSSLIB_RECTANGLE_LEAST_SQUARES_EQUILIBRIUM_C_V, MSSLIB_RECTANGLE_LEAST_SQUARES_EQUILIBRIUM_C_D, MSSLIB_RECTANGLE_LEAST_SQUARES_EQUILIBRIUM_N_OUT };
/* rectangle_least_squares_equilibrium: Least-squares springs of an a x b rectangle (r = b/a), plane stress, nu = 1/3, restricted to elements in equilibrium at rest (spring tensions balance at every node), per element: k_h (the 2 edges along x, length a), k_v (the 2 edges along y, length b = r a), k_d (the 2 diagonals) and rest-length factors c_h, c_v, c_d (rest length = c times the rest distance). Edge constants add up over the elements sharing the edge. Equal to rectangle_least_squares at r = 1; k and c are positive for every r.
 * Writes out[0..5] = (k_h, k_v, k_d, c_h, c_v, c_d). */
MSSLIB_API void msslib_rectangle_least_squares_equilibrium(double E, double t, double r, double *out)
{
    const double _c0 = pow(r, 4);
    const double _c1 = 5*_c0;
    const double _c2 = pow(r, 2);
    const double _c3 = 14*_c2;
    const double _c4 = _c1 + _c3;
    const double _c5 = _c4 + 1;
    const double _c6 = E*t/(_c4 + 5);
    const double _c7 = (3.0/8.0)*_c6;
    const double _c8 = 1.0/r;
    const double _c9 = _c0 + _c3 + 5;
    const double _c10 = _c1 + 5;
    const double _c11 = _c10 + 32*_c2;
    const double _c12 = pow(r, 6);
    out[0] = _c5*_c7*r;
    out[1] = _c7*_c8*_c9;
    out[2] = (1.0/8.0)*_c11*_c6*_c8*(_c2 + 1);
    out[3] = (1.0/6.0)*(91*_c0 + 35*_c12 + 13*_c2 + 5)/(_c2*_c5);
    out[4] = (1.0/6.0)*(13*_c0 + 5*_c12 + 91*_c2 + 35)/_c9;
    out[5] = (1.0/2.0)*(_c10 + 62*_c2)/_c11;
}

enum { MSSLIB_RECTANGLE_LEAST_SQUARES_NU_K_H, MSSLIB_RECTANGLE_LEAST_SQUARES_NU_K_V, MSSLIB_RECTANGLE_LEAST_SQUARES_NU_K_D, MSSLIB_RECTANGLE_LEAST_SQUARES_NU_C_H, MSSLIB_RECTANGLE_LEAST_SQUARES_NU_C_V, MSSLIB_RECTANGLE_LEAST_SQUARES_NU_C_D, MSSLIB_RECTANGLE_LEAST_SQUARES_NU_N_OUT };
/* rectangle_least_squares_nu: Least-squares springs of an a x b rectangle (r = b/a), plane stress, any Poisson's ratio nu, per element: k_h (the 2 edges along x, length a), k_v (the 2 edges along y, length b = r a), k_d (the 2 diagonals) and rest-length factors c_h, c_v, c_d (rest length = c times the rest distance). Edge constants add up over the elements sharing the edge. rectangle_least_squares is its value at nu = 1/3; not in equilibrium at rest.
 * Writes out[0..5] = (k_h, k_v, k_d, c_h, c_v, c_d). */
MSSLIB_API void msslib_rectangle_least_squares_nu(double E, double nu, double t, double r, double *out)
{
    const double _c0 = 2*nu;
    const double _c1 = pow(r, 2);
    const double _c2 = pow(r, 4);
    const double _c3 = pow(r, 6);
    const double _c4 = 3*nu;
    const double _c5 = 7*nu;
    const double _c6 = _c0 + _c1*_c4 - 5*_c1 + _c2*_c5 + 35*_c2 + 8*_c3 - 2;
    const double _c7 = nu + 1;
    const double _c8 = (1.0/24.0)*E*t/(_c7*r*(nu - 1)*(4*_c1 + _c2 + 1));
    const double _c9 = 2*_c3;
    const double _c10 = _c1*_c5;
    const double _c11 = _c0*_c3 + 35*_c1 + _c10 + _c2*_c4 - 5*_c2 - _c9 + 8;
    const double _c12 = _c1 + 1;
    const double _c13 = -_c0*_c2 - _c0 + 23*_c1 + _c10 + 2*_c2 + 2;
    const double _c14 = 2*_c7;
    const double _c15 = 3*r;
    out[0] = -_c6*_c8;
    out[1] = -_c11*_c8;
    out[2] = -_c12*_c13*_c8;
    out[3] = _c14*(_c12 + 14*_c2 + _c9)/_c6;
    out[4] = _c14*(14*_c1 + _c2 + _c3 + 2)/_c11;
    out[5] = _c14*(-_c1 + _c15 + 1)*(_c1 + _c15 - 1)/_c13;
}

MSSLIB_END_DECLS

#endif /* MSSLIB_RECTANGLE_H */
