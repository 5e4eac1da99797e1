// Generated from derivations/elements/tetrahedron_lsq.py by `python -m derivations.codegen`. Do not edit.
// source-sha256: 3cd6b1a2973f61017b23473b09935e1fb9ab75164cbff052670e0a5c394210ce
// body-sha256: d3424e9148ad293e12c80e2b2d4b32e79d8c09b389dab6212e6df4cdcbe315f0
/* Tetrahedron of any shape, six springs fitted to its own linear element by least squares (Natsupakpong and Cavusoglu 2010, normal equations), in C99 (units and linkage: msslib_api.h).
 * Printed from the expressions of msslib/generated/tetrahedron_lsq.py (derivations/elements/tetrahedron_lsq.py). */
#ifndef MSSLIB_TETRAHEDRON_LSQ_H
#define MSSLIB_TETRAHEDRON_LSQ_H

#include "msslib_api.h"

MSSLIB_BEGIN_DECLS

enum { MSSLIB_LSQ_TETRAHEDRON_GRAM_G_00, MSSLIB_LSQ_TETRAHEDRON_GRAM_G_01, MSSLIB_LSQ_TETRAHEDRON_GRAM_G_02, MSSLIB_LSQ_TETRAHEDRON_GRAM_G_03, MSSLIB_LSQ_TETRAHEDRON_GRAM_G_04, MSSLIB_LSQ_TETRAHEDRON_GRAM_G_05, MSSLIB_LSQ_TETRAHEDRON_GRAM_G_11, MSSLIB_LSQ_TETRAHEDRON_GRAM_G_12, MSSLIB_LSQ_TETRAHEDRON_GRAM_G_13, MSSLIB_LSQ_TETRAHEDRON_GRAM_G_14, MSSLIB_LSQ_TETRAHEDRON_GRAM_G_15, MSSLIB_LSQ_TETRAHEDRON_GRAM_G_22, MSSLIB_LSQ_TETRAHEDRON_GRAM_G_23, MSSLIB_LSQ_TETRAHEDRON_GRAM_G_24, MSSLIB_LSQ_TETRAHEDRON_GRAM_G_25, MSSLIB_LSQ_TETRAHEDRON_GRAM_G_33, MSSLIB_LSQ_TETRAHEDRON_GRAM_G_34, MSSLIB_LSQ_TETRAHEDRON_GRAM_G_35, MSSLIB_LSQ_TETRAHEDRON_GRAM_G_44, MSSLIB_LSQ_TETRAHEDRON_GRAM_G_45, MSSLIB_LSQ_TETRAHEDRON_GRAM_G_55, MSSLIB_LSQ_TETRAHEDRON_GRAM_N_OUT };
/* lsq_tetrahedron_gram: Gram matrix G_pq = <K_p, K_q> (upper triangle, dimensionless) of the unit springs of one tetrahedron with nodes (0, 0, 0), (a, 0, 0), (x2, y2, 0), (x3, y3, z3), y2 > 0, z3 > 0 (positively oriented); edges 0-1, 0-2, 0-3, 1-2, 1-3, 2-3. The per-element spring constants (N/m, summed over the tetrahedra sharing an edge) solve G k = b.
 * Writes out[0..20] = (G_00, G_01, G_02, G_03, G_04, G_05, G_11, G_12, G_13, G_14, G_15, G_22, G_23, G_24, G_25, G_33, G_34, G_35, G_44, G_45, G_55). */
MSSLIB_API void msslib_lsq_tetrahedron_gram(double a, double x2, double y2, double x3, double y3, double z3, double *out)
{
    const double _c0 = pow(x2, 2);
    const double _c1 = pow(y2, 2);
    const double _c2 = _c0 + _c1;
    const double _c3 = 1.0/_c2;
    const double _c4 = pow(x3, 2);
    const double _c5 = _c4 + pow(y3, 2) + pow(z3, 2);
    const double _c6 = 1.0/_c5;
    const double _c7 = pow(a, 2);
    const double _c8 = a*x2;
    const double _c9 = 1.0/(_c2 + _c7 - 2*_c8);
    const double _c10 = a*x3;
    const double _c11 = 1.0/(-2*_c10 + _c5 + _c7);
    const double _c12 = x2*x3;
    const double _c13 = y2*y3;
    const double _c14 = _c12 + _c13;
    const double _c15 = -_c8;
    const double _c16 = -_c12 - _c13;
    const double _c17 = 1.0/(-2*_c12 - 2*_c13 + _c2 + _c5);
    const double _c18 = -_c10;
    const double _c19 = _c18 + _c5;
    const double _c20 = _c14 + _c18;
    out[0] = 4;
    out[1] = _c0*_c3;
    out[2] = _c4*_c6;
    out[3] = _c9*pow(a - x2, 2);
    out[4] = _c11*pow(a - x3, 2);
    out[5] = 0;
    out[6] = 4;
    out[7] = pow(_c14, 2)*_c3*_c6;
    out[8] = _c3*_c9*pow(_c15 + _c2, 2);
    out[9] = 0;
    out[10] = _c17*_c3*pow(_c16 + _c2, 2);
    out[11] = 4;
    out[12] = 0;
    out[13] = _c11*pow(_c19, 2)*_c6;
    out[14] = _c17*_c6*pow(_c16 + _c5, 2);
    out[15] = 4;
    out[16] = _c11*_c9*pow(_c15 + _c20 + _c7, 2);
    out[17] = _c17*_c9*pow(-_c0 - _c1 + _c20 + _c8, 2);
    out[18] = 4;
    out[19] = _c11*_c17*pow(_c16 + _c19 + _c8, 2);
    out[20] = 4;
}

enum { MSSLIB_LSQ_TETRAHEDRON_RHS_B_0, MSSLIB_LSQ_TETRAHEDRON_RHS_B_1, MSSLIB_LSQ_TETRAHEDRON_RHS_B_2, MSSLIB_LSQ_TETRAHEDRON_RHS_B_3, MSSLIB_LSQ_TETRAHEDRON_RHS_B_4, MSSLIB_LSQ_TETRAHEDRON_RHS_B_5, MSSLIB_LSQ_TETRAHEDRON_RHS_N_OUT };
/* lsq_tetrahedron_rhs: Right-hand side b_p = <K_p, K_FEM> (N/m) of one tetrahedron with nodes (0, 0, 0), (a, 0, 0), (x2, y2, 0), (x3, y3, z3), y2 > 0, z3 > 0 (positively oriented); edges 0-1, 0-2, 0-3, 1-2, 1-3, 2-3. The per-element spring constants (N/m, summed over the tetrahedra sharing an edge) solve G k = b.
 * Writes out[0..5] = (b_0, b_1, b_2, b_3, b_4, b_5). */
MSSLIB_API void msslib_lsq_tetrahedron_rhs(double E, double nu, double a, double x2, double y2, double x3, double y3, double z3, double *out)
{
    const double _c0 = y2*y3;
    const double _c1 = 4*a;
    const double _c2 = _c1*x2;
    const double _c3 = _c0*_c2;
    const double _c4 = _c1*x3;
    const double _c5 = _c0*_c4;
    const double _c6 = x2*x3;
    const double _c7 = _c0*_c6;
    const double _c8 = pow(y3, 2);
    const double _c9 = _c2*_c8;
    const double _c10 = pow(z3, 2);
    const double _c11 = _c10*_c2;
    const double _c12 = pow(y2, 2);
    const double _c13 = _c1*_c12;
    const double _c14 = _c13*x3;
    const double _c15 = pow(a, 2);
    const double _c16 = 2*_c0;
    const double _c17 = 8*nu;
    const double _c18 = _c17*a;
    const double _c19 = _c18*x2;
    const double _c20 = _c0*_c19;
    const double _c21 = _c18*x3;
    const double _c22 = _c0*_c21;
    const double _c23 = _c12*_c15;
    const double _c24 = _c15*_c8;
    const double _c25 = _c10*_c15;
    const double _c26 = pow(x2, 2);
    const double _c27 = _c26*_c8;
    const double _c28 = 4*_c27;
    const double _c29 = _c10*_c26;
    const double _c30 = 4*_c29;
    const double _c31 = pow(x3, 2);
    const double _c32 = _c12*_c31;
    const double _c33 = 4*_c32;
    const double _c34 = _c10*_c12;
    const double _c35 = 8*_c34;
    const double _c36 = _c19*_c8;
    const double _c37 = _c10*_c19;
    const double _c38 = _c12*_c18;
    const double _c39 = 4*_c15;
    const double _c40 = _c0*_c39;
    const double _c41 = _c40*nu;
    const double _c42 = 2*nu;
    const double _c43 = _c35*nu;
    const double _c44 = (1.0/12.0)*E/(y2*z3*(_c42 - 1)*(nu + 1));
    const double _c45 = _c44/a;
    const double _c46 = _c12 + _c26;
    const double _c47 = pow(y2, 4);
    const double _c48 = _c15*_c47;
    const double _c49 = _c23*_c26;
    const double _c50 = _c24*_c26;
    const double _c51 = 4*_c50;
    const double _c52 = _c25*_c26;
    const double _c53 = 4*_c52;
    const double _c54 = 2*a;
    const double _c55 = _c54*x3;
    const double _c56 = pow(y2, 3)*y3;
    const double _c57 = pow(x2, 3);
    const double _c58 = _c1*_c57;
    const double _c59 = _c15*_c17;
    const double _c60 = _c18*_c57;
    const double _c61 = _c4*_c56;
    const double _c62 = _c4*nu;
    const double _c63 = _c54*x2;
    const double _c64 = _c0*_c54;
    const double _c65 = _c12*_c26;
    const double _c66 = _c12*_c9;
    const double _c67 = _c12*_c8;
    const double _c68 = _c43*a;
    const double _c69 = _c0*_c59;
    const double _c70 = _c26*_c5;
    const double _c71 = _c2*nu;
    const double _c72 = _c0*nu;
    const double _c73 = pow(x2, 4);
    const double _c74 = _c73*_c8;
    const double _c75 = _c10*_c73;
    const double _c76 = _c31*_c47;
    const double _c77 = _c10*_c47;
    const double _c78 = _c31*_c65;
    const double _c79 = _c12*_c27;
    const double _c80 = 2*_c10;
    const double _c81 = 2*_c6;
    const double _c82 = _c16*x3;
    const double _c83 = 4*nu;
    const double _c84 = _c10*_c83;
    const double _c85 = _c6*_c83;
    const double _c86 = _c0*_c83;
    const double _c87 = _c86*x3;
    const double _c88 = _c42*_c74 + _c42*_c75 + _c42*_c76 + _c42*_c77 + _c42*_c78 + _c42*_c79 + _c56*_c81 - _c56*_c85 + _c57*_c82 - _c57*_c87 - _c65*_c80 + _c65*_c84 - _c74 - _c75 - _c76 - _c77 - _c78 - _c79;
    const double _c89 = _c10*_c23;
    const double _c90 = _c12*_c24;
    const double _c91 = _c17*_c89 + _c17*_c90 - 8*_c89 - 4*_c90;
    const double _c92 = _c10 + _c31 + _c8;
    const double _c93 = pow(y3, 4);
    const double _c94 = _c15*_c93;
    const double _c95 = pow(z3, 4);
    const double _c96 = _c15*_c95;
    const double _c97 = _c24*_c31;
    const double _c98 = _c25*_c31;
    const double _c99 = _c23*_c31;
    const double _c100 = 4*_c99;
    const double _c101 = pow(x3, 3);
    const double _c102 = y2*pow(y3, 3);
    const double _c103 = _c31*_c8;
    const double _c104 = _c10*_c31;
    const double _c105 = _c14*_c8;
    const double _c106 = _c0*_c25;
    const double _c107 = _c3*_c31;
    const double _c108 = _c0*_c55;
    const double _c109 = _c10*nu;
    const double _c110 = _c26*_c93;
    const double _c111 = _c26*_c95;
    const double _c112 = _c12*pow(x3, 4);
    const double _c113 = _c12*_c95;
    const double _c114 = _c27*_c31;
    const double _c115 = _c29*_c31;
    const double _c116 = _c103*_c12;
    const double _c117 = _c34*_c8;
    const double _c118 = _c16*x2;
    const double _c119 = _c86*x2;
    const double _c120 = _c10*_c81;
    const double _c121 = _c0*_c120 + _c101*_c118 - _c101*_c119 + _c102*_c81 - _c102*_c85 + _c109*_c28 + _c109*_c33 + _c110*_c42 - _c110 + _c111*_c42 - _c111 + _c112*_c42 - _c112 + _c113*_c42 - _c113 + _c114*_c42 - _c114 + _c115*_c42 - _c115 + _c116*_c42 - _c116 + _c117*_c42 - _c117 - _c27*_c80 - _c32*_c80 - _c7*_c84;
    const double _c122 = pow(a, 4);
    const double _c123 = _c122*_c8;
    const double _c124 = _c10*_c122;
    const double _c125 = pow(a, 3);
    const double _c126 = a*nu;
    const double _c127 = -_c0*_c15*_c81 + _c41*_c6 + _c42*_c90 + _c83*_c89 - 6*_c89 - _c90;
    const double _c128 = _c12*_c122;
    const double _c129 = _c126*x3;
    const double _c130 = _c0*_c63;
    const double _c131 = 2*_c8;
    out[0] = _c45*(_c11 + _c14 + _c15*_c16 + _c17*_c27 + _c17*_c29 + _c17*_c32 + _c20 + _c22 + _c23*_c42 - _c23 + _c24*_c42 - _c24 + _c25*_c42 - _c25 - _c28 - _c3 - _c30 - _c33 - _c35 - _c36 - _c37 - _c38*x3 - _c41 + _c43 - _c5 - 16*_c7*nu + 8*_c7 + _c9);
    out[1] = _c45*(_c10*_c58 - _c10*_c60 + _c17*_c50 + _c17*_c52 - _c19*_c67 + _c2*_c34 + _c21*_c56 + _c22*_c26 + _c26*_c40 - _c26*_c69 + _c39*_c56 + _c42*_c48 + _c42*_c49 + _c47*_c55 - _c47*_c62 - _c48 - _c49 - _c51 - _c53 + _c55*_c65 - _c56*_c59 - _c56*_c63 + _c56*_c71 - _c57*_c64 + _c58*_c72 + _c58*_c8 - _c60*_c8 - _c61 - _c62*_c65 + _c66 - _c68*x2 - _c70 + _c88 + _c91)/_c46;
    out[2] = _c45*(-_c0*_c11 + _c0*_c37 + _c1*_c101*_c72 - _c10*_c108 - _c10*_c36 + _c10*_c9 - _c100 + _c101*_c13 - _c101*_c38 - _c101*_c64 + _c102*_c19 - _c102*_c2 + _c102*_c39 - _c102*_c55 - _c102*_c59 + _c102*_c62 + _c103*_c63 - _c103*_c71 + _c104*_c63 - _c104*_c71 + _c105 - _c106*_c17 + 4*_c106 - _c107 + _c109*_c5 + _c121 + _c17*_c99 + _c20*_c31 - _c21*_c67 - _c24*_c80 + _c24*_c84 + _c31*_c40 - _c31*_c69 + _c34*_c4 + _c42*_c94 + _c42*_c96 + _c42*_c97 + _c42*_c98 + _c63*_c93 + _c63*_c95 - _c68*x3 - _c71*_c93 - _c71*_c95 + _c91 - _c94 - _c96 - _c97 - _c98)/_c92;
    out[3] = _c45*(-_c108*_c26 + _c123*_c42 - _c123 + _c124*_c42 - _c124 + _c125*_c82 - _c125*_c87 - _c126*_c33*x2 + _c127 + _c32*_c63 + _c42*_c99 + 2*_c50 - _c51*nu + 2*_c52 - _c53*nu + _c55*_c56 - _c61*nu - _c63*_c67 + _c66*nu + _c70*nu + _c88 - _c99)/(_c15 + _c46 - _c63);
    out[4] = _c45*(_c10*_c130 - _c100*nu + _c102*_c63 - _c102*_c71 + _c105*nu + _c107*nu - _c11*_c72 + _c118*_c125 - _c119*_c125 + _c121 + _c127 + _c128*_c42 - _c128 - _c129*_c28 - _c129*_c30 - _c130*_c31 + _c27*_c55 + _c29*_c55 + _c42*_c50 + _c42*_c52 - _c50 - _c52 - _c55*_c67 + 2*_c99)/(_c15 - _c55 + _c92);
    out[5] = _c44*a*(-_c10*_c131 + _c103*_c42 - _c103 + _c104*_c42 - _c104 + _c12*_c131 + _c12*_c81 - _c12*_c85 + _c120 - _c16*_c26 - _c16*_c31 - _c17*_c7 + _c26*_c86 + _c27*_c42 - _c27 + _c29*_c42 - _c29 + _c31*_c86 + _c32*_c42 - _c32 + _c34*_c83 - 6*_c34 + _c42*_c47 + _c42*_c65 + _c42*_c93 + _c42*_c95 - _c47 - _c6*_c84 - _c65 - _c67*_c83 + 4*_c7 + _c8*_c81 + _c8*_c84 - _c8*_c85 - _c93 - _c95)/(-_c16 + _c46 - _c81 + _c92);
}

MSSLIB_END_DECLS

#endif /* MSSLIB_TETRAHEDRON_LSQ_H */
