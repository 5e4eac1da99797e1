// Generated from derivations/ by `python -m derivations.codegen`. Do not edit.
// source-sha256: a3482487f48e97bcf813af674b8e238b6a6ed2b563d838dbd97c8c52b2117f24
// body-sha256: 5ceba7b2a30e6d690d2d5155aca5c1712604068917890b031bb7363351837576
/* Spring constants, rest-length factors, volume coefficients and the energy, gradient and
 * Hessian kernels of msslib's mass-spring models, in C99.
 *
 * Printed by SymPy's C99 printer from the expressions that the Python modules of
 * msslib/generated are printed from (the modules of derivations/), with the same common
 * subexpressions; `python -m derivations.codegen` writes both, do not edit.
 * SI units: E in Pa, lengths in m, spring constants in N/m, energies in J, gradients in N,
 * Hessians in N/m (row-major, node by node: x0, y0(, z0), x1, ...).
 * Functions are `static inline` unless MSSLIB_API is defined before this header is
 * included (define it empty to compile them with external linkage, e.g. into a library).
 * Link with -lm. */
#ifndef MSSLIB_MSS_H
#define MSSLIB_MSS_H

#include <math.h>

#ifndef MSSLIB_API
#define MSSLIB_API static inline
#endif

#ifdef __cplusplus
extern "C" {
#endif

/* ---- derivations/triangle.py: Equilateral triangle, plane stress (Lloyd et al. eq. 8; van Gelder, eq. 9) ---- */

/* lloyd_triangle: Spring constant of each edge of an equilateral triangle, per element (sum over the triangles sharing the edge). Exact for nu = 1/3.
 * Returns k. */
MSSLIB_API double msslib_lloyd_triangle(double E, double t)
{
    return (1.0/4.0)*sqrt(3)*E*t;
}

/* van_gelder_triangle: Van Gelder's spring constant, per element: E t A_e / l^2.
 * Returns k. */
MSSLIB_API double msslib_van_gelder_triangle(double E, double t, double A_e, double l)
{
    return A_e*E*t/pow(l, 2);
}

/* ---- derivations/square.py: Square with prestrained springs, plane stress (Lloyd et al. eqs. 10-11) ---- */

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

/* ---- derivations/rectangle.py: Rectangle of aspect ratio r, plane stress, six prestrained springs (generalising Lloyd et al. Sec. 4.1) ---- */

#define MSSLIB_RECTANGLE_LEAST_SQUARES_N_OUT 6
#define MSSLIB_RECTANGLE_LEAST_SQUARES_K_H 0
#define MSSLIB_RECTANGLE_LEAST_SQUARES_K_V 1
#define MSSLIB_RECTANGLE_LEAST_SQUARES_K_D 2
#define MSSLIB_RECTANGLE_LEAST_SQUARES_C_H 3
#define MSSLIB_RECTANGLE_LEAST_SQUARES_C_V 4
#define MSSLIB_RECTANGLE_LEAST_SQUARES_C_D 5

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

#define MSSLIB_RECTANGLE_LEAST_SQUARES_EQUILIBRIUM_N_OUT 6
#define MSSLIB_RECTANGLE_LEAST_SQUARES_EQUILIBRIUM_K_H 0
#define MSSLIB_RECTANGLE_LEAST_SQUARES_EQUILIBRIUM_K_V 1
#define MSSLIB_RECTANGLE_LEAST_SQUARES_EQUILIBRIUM_K_D 2
#define MSSLIB_RECTANGLE_LEAST_SQUARES_EQUILIBRIUM_C_H 3
#define MSSLIB_RECTANGLE_LEAST_SQUARES_EQUILIBRIUM_C_V 4
#define MSSLIB_RECTANGLE_LEAST_SQUARES_EQUILIBRIUM_C_D 5

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

#define MSSLIB_RECTANGLE_LEAST_SQUARES_NU_N_OUT 6
#define MSSLIB_RECTANGLE_LEAST_SQUARES_NU_K_H 0
#define MSSLIB_RECTANGLE_LEAST_SQUARES_NU_K_V 1
#define MSSLIB_RECTANGLE_LEAST_SQUARES_NU_K_D 2
#define MSSLIB_RECTANGLE_LEAST_SQUARES_NU_C_H 3
#define MSSLIB_RECTANGLE_LEAST_SQUARES_NU_C_V 4
#define MSSLIB_RECTANGLE_LEAST_SQUARES_NU_C_D 5

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

/* ---- derivations/tetrahedron.py: Regular tetrahedron, least squares (Lloyd et al. eqs. 12-14) ---- */

/* lloyd_tetrahedron: Per-element spring constant of a regular tetrahedron of edge l (least squares at nu = 1/4, eq. 12); use the equivalent edge length of eq. 13 for other shapes; sum over the tetrahedra sharing the edge.
 * Returns k. */
MSSLIB_API double msslib_lloyd_tetrahedron(double E, double l)
{
    return (2.0/25.0)*sqrt(2)*E*l;
}

/* lloyd_tetrahedron_general_nu: Least-squares spring constant for any nu (per element).
 * Returns k. */
MSSLIB_API double msslib_lloyd_tetrahedron_general_nu(double E, double nu, double l)
{
    return (1.0/15.0)*sqrt(2)*E*l*(nu - 1)/((nu + 1)*(2*nu - 1));
}

#define MSSLIB_LLOYD_TETRAHEDRON_VOLUME_N_OUT 2
#define MSSLIB_LLOYD_TETRAHEDRON_VOLUME_K 0
#define MSSLIB_LLOYD_TETRAHEDRON_VOLUME_K_VOLUME 1

/* lloyd_tetrahedron_volume: Per-element spring constant and volume-energy coefficient k_V of E_V = k_V/(2 V0^2)(V - V0)^2, least squares for any nu (eq. 14 is the case nu = 1/4).
 * Writes out[0..1] = (k, k_volume). */
MSSLIB_API void msslib_lloyd_tetrahedron_volume(double E, double nu, double l, double *out)
{
    const double _c0 = sqrt(2)*E/(nu + 1);
    out[0] = (2.0/21.0)*_c0*l;
    out[1] = -1.0/84.0*_c0*pow(l, 3)*(13*nu - 3)/(2*nu - 1);
}

/* equivalent_edge_length: Edge of the regular tetrahedron of volume V (eq. 13).
 * Returns l. */
MSSLIB_API double msslib_equivalent_edge_length(double V)
{
    return sqrt(2)*cbrt(3)*cbrt(V);
}

#define MSSLIB_LLOYD_TETRAHEDRON_VOLUME_PUBLISHED_N_OUT 2
#define MSSLIB_LLOYD_TETRAHEDRON_VOLUME_PUBLISHED_K 0
#define MSSLIB_LLOYD_TETRAHEDRON_VOLUME_PUBLISHED_K_VOLUME 1

/* lloyd_tetrahedron_volume_published: Lloyd et al.'s eq. 14 as printed (the optimum at nu = 1/4).
 * Writes out[0..1] = (k, k_volume). */
MSSLIB_API void msslib_lloyd_tetrahedron_volume_published(double E, double l, double *out)
{
    const double _c0 = sqrt(2)*E;
    out[0] = (8.0/105.0)*_c0*l;
    out[1] = (1.0/210.0)*_c0*pow(l, 3);
}

/* ---- derivations/cube_baudet.py: Cube with edge and inner-diagonal springs and orthogonal correction (Baudet et al.) ---- */

#define MSSLIB_BAUDET_CUBE_N_OUT 3
#define MSSLIB_BAUDET_CUBE_K_EDGE 0
#define MSSLIB_BAUDET_CUBE_K_DIAGONAL 1
#define MSSLIB_BAUDET_CUBE_CORRECTION_FACTOR 2

/* baudet_cube: Per-element constants of a cube of edge a: edge springs (sum over the cubes sharing the edge), inner diagonals, and the factor c of the correction force F_perp = c F_i applied, as a total per face, on each face orthogonal to the elongation force F_i (Baudet eqs. 7-8).
 * Writes out[0..2] = (k_edge, k_diagonal, correction_factor). */
MSSLIB_API void msslib_baudet_cube(double E, double nu, double a, double *out)
{
    const double _c0 = E*a/(nu + 1);
    out[0] = (1.0/8.0)*_c0*(4*nu + 1);
    out[1] = (3.0/8.0)*_c0;
    out[2] = 1.0/2.0 - 2*nu;
}

#define MSSLIB_BAUDET_CUBE_PUBLISHED_N_OUT 3
#define MSSLIB_BAUDET_CUBE_PUBLISHED_K_EDGE 0
#define MSSLIB_BAUDET_CUBE_PUBLISHED_K_DIAGONAL 1
#define MSSLIB_BAUDET_CUBE_PUBLISHED_CORRECTION_FACTOR 2

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

/* ---- derivations/cube_golec.py: Cube with edge, face and inner springs and volume correction (Golec et al.) ---- */

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

/* ---- derivations/kernels.py: Energy, gradient and Hessian kernels ---- */

/* spring2d_energy: Spring k/2 (|x1 - x0| - L0)^2 in 2D. Energy [J].
 * Returns energy. */
MSSLIB_API double msslib_spring2d_energy(double x0, double y0, double x1, double y1, double k, double L0)
{
    return (1.0/2.0)*k*pow(L0 - sqrt(pow(x0 - x1, 2) + pow(y0 - y1, 2)), 2);
}

#define MSSLIB_SPRING2D_GRADIENT_N_OUT 4

/* spring2d_gradient: Spring k/2 (|x1 - x0| - L0)^2 in 2D. Gradient dW/dx [N] (the force is minus this), 4 entries, node by node.
 * Writes out[0..3] = (g0, g1, g2, g3). */
MSSLIB_API void msslib_spring2d_gradient(double x0, double y0, double x1, double y1, double k, double L0, double *out)
{
    const double _c0 = x0 - x1;
    const double _c1 = y0 - y1;
    const double _c2 = sqrt(pow(_c0, 2) + pow(_c1, 2));
    const double _c3 = k*(L0 - _c2)/_c2;
    const double _c4 = _c0*_c3;
    const double _c5 = _c1*_c3;
    out[0] = -_c4;
    out[1] = -_c5;
    out[2] = _c4;
    out[3] = _c5;
}

#define MSSLIB_SPRING2D_HESSIAN_N_OUT 16

/* spring2d_hessian: Spring k/2 (|x1 - x0| - L0)^2 in 2D. Hessian [N/m], 4x4 row-major.
 * Writes out[0..15] = (h0, h1, h2, h3, h4, h5, h6, h7, h8, h9, h10, h11, h12, h13, h14, h15). */
MSSLIB_API void msslib_spring2d_hessian(double x0, double y0, double x1, double y1, double k, double L0, double *out)
{
    const double _c0 = x0 - x1;
    const double _c1 = pow(_c0, 2);
    const double _c2 = y0 - y1;
    const double _c3 = pow(_c2, 2);
    const double _c4 = _c1 + _c3;
    const double _c5 = 1.0/_c4;
    const double _c6 = sqrt(_c4);
    const double _c7 = L0 - _c6;
    const double _c8 = -_c7/_c6;
    const double _c9 = _c7/pow(_c4, 3.0/2.0);
    const double _c10 = _c1*_c5 + _c1*_c9 + _c8;
    const double _c11 = _c10*k;
    const double _c12 = _c0*_c2*k*(_c5 + _c9);
    const double _c13 = -_c10*k;
    const double _c14 = -_c12;
    const double _c15 = _c3*_c5 + _c3*_c9 + _c8;
    const double _c16 = _c15*k;
    const double _c17 = -_c15*k;
    out[0] = _c11;
    out[1] = _c12;
    out[2] = _c13;
    out[3] = _c14;
    out[4] = _c12;
    out[5] = _c16;
    out[6] = _c14;
    out[7] = _c17;
    out[8] = _c13;
    out[9] = _c14;
    out[10] = _c11;
    out[11] = _c12;
    out[12] = _c14;
    out[13] = _c17;
    out[14] = _c12;
    out[15] = _c16;
}

/* spring3d_energy: Spring k/2 (|x1 - x0| - L0)^2 in 3D. Energy [J].
 * Returns energy. */
MSSLIB_API double msslib_spring3d_energy(double x0, double y0, double z0, double x1, double y1, double z1, double k, double L0)
{
    return (1.0/2.0)*k*pow(L0 - sqrt(pow(x0 - x1, 2) + pow(y0 - y1, 2) + pow(z0 - z1, 2)), 2);
}

#define MSSLIB_SPRING3D_GRADIENT_N_OUT 6

/* spring3d_gradient: Spring k/2 (|x1 - x0| - L0)^2 in 3D. Gradient dW/dx [N] (the force is minus this), 6 entries, node by node.
 * Writes out[0..5] = (g0, g1, g2, g3, g4, g5). */
MSSLIB_API void msslib_spring3d_gradient(double x0, double y0, double z0, double x1, double y1, double z1, double k, double L0, double *out)
{
    const double _c0 = x0 - x1;
    const double _c1 = y0 - y1;
    const double _c2 = z0 - z1;
    const double _c3 = sqrt(pow(_c0, 2) + pow(_c1, 2) + pow(_c2, 2));
    const double _c4 = k*(L0 - _c3)/_c3;
    const double _c5 = _c0*_c4;
    const double _c6 = _c1*_c4;
    const double _c7 = _c2*_c4;
    out[0] = -_c5;
    out[1] = -_c6;
    out[2] = -_c7;
    out[3] = _c5;
    out[4] = _c6;
    out[5] = _c7;
}

#define MSSLIB_SPRING3D_HESSIAN_N_OUT 36

/* spring3d_hessian: Spring k/2 (|x1 - x0| - L0)^2 in 3D. Hessian [N/m], 6x6 row-major.
 * Writes out[0..35] = (h0, h1, h2, h3, h4, h5, h6, h7, h8, h9, h10, h11, h12, h13, h14, h15, h16, h17, h18, h19, h20, h21, h22, h23, h24, h25, h26, h27, h28, h29, h30, h31, h32, h33, h34, h35). */
MSSLIB_API void msslib_spring3d_hessian(double x0, double y0, double z0, double x1, double y1, double z1, double k, double L0, double *out)
{
    const double _c0 = x0 - x1;
    const double _c1 = pow(_c0, 2);
    const double _c2 = y0 - y1;
    const double _c3 = pow(_c2, 2);
    const double _c4 = z0 - z1;
    const double _c5 = pow(_c4, 2);
    const double _c6 = _c1 + _c3 + _c5;
    const double _c7 = 1.0/_c6;
    const double _c8 = sqrt(_c6);
    const double _c9 = L0 - _c8;
    const double _c10 = -_c9/_c8;
    const double _c11 = _c9/pow(_c6, 3.0/2.0);
    const double _c12 = _c1*_c11 + _c1*_c7 + _c10;
    const double _c13 = _c12*k;
    const double _c14 = _c11 + _c7;
    const double _c15 = _c0*_c14*k;
    const double _c16 = _c15*_c2;
    const double _c17 = _c15*_c4;
    const double _c18 = -_c12*k;
    const double _c19 = -_c16;
    const double _c20 = -_c17;
    const double _c21 = _c10 + _c11*_c3 + _c3*_c7;
    const double _c22 = _c21*k;
    const double _c23 = _c14*_c2*_c4*k;
    const double _c24 = -_c21*k;
    const double _c25 = -_c23;
    const double _c26 = _c10 + _c11*_c5 + _c5*_c7;
    const double _c27 = _c26*k;
    const double _c28 = -_c26*k;
    out[0] = _c13;
    out[1] = _c16;
    out[2] = _c17;
    out[3] = _c18;
    out[4] = _c19;
    out[5] = _c20;
    out[6] = _c16;
    out[7] = _c22;
    out[8] = _c23;
    out[9] = _c19;
    out[10] = _c24;
    out[11] = _c25;
    out[12] = _c17;
    out[13] = _c23;
    out[14] = _c27;
    out[15] = _c20;
    out[16] = _c25;
    out[17] = _c28;
    out[18] = _c18;
    out[19] = _c19;
    out[20] = _c20;
    out[21] = _c13;
    out[22] = _c16;
    out[23] = _c17;
    out[24] = _c19;
    out[25] = _c24;
    out[26] = _c25;
    out[27] = _c16;
    out[28] = _c22;
    out[29] = _c23;
    out[30] = _c20;
    out[31] = _c25;
    out[32] = _c28;
    out[33] = _c17;
    out[34] = _c23;
    out[35] = _c27;
}

/* tet_volume_energy: Tetrahedron volume energy k_v/(2 V0^2) (V - V0)^2 (Lloyd et al. App. C.2). Energy [J].
 * Returns energy. */
MSSLIB_API double msslib_tet_volume_energy(double x0, double y0, double z0, double x1, double y1, double z1, double x2, double y2, double z2, double x3, double y3, double z3, double k_v, double V0)
{
    const double _c0 = (1.0/6.0)*x0;
    const double _c1 = _c0*y1;
    const double _c2 = _c0*y2;
    const double _c3 = _c0*y3;
    const double _c4 = (1.0/6.0)*x1;
    const double _c5 = _c4*y0;
    const double _c6 = _c4*y2;
    const double _c7 = _c4*y3;
    const double _c8 = (1.0/6.0)*x2;
    const double _c9 = _c8*y0;
    const double _c10 = _c8*y1;
    const double _c11 = _c8*y3;
    const double _c12 = (1.0/6.0)*x3;
    const double _c13 = _c12*y0;
    const double _c14 = _c12*y1;
    const double _c15 = _c12*y2;
    return (1.0/2.0)*k_v*pow(V0 + _c1*z2 - _c1*z3 - _c10*z0 + _c10*z3 + _c11*z0 - _c11*z1 - _c13*z1 + _c13*z2 + _c14*z0 - _c14*z2 - _c15*z0 + _c15*z1 - _c2*z1 + _c2*z3 + _c3*z1 - _c3*z2 - _c5*z2 + _c5*z3 + _c6*z0 - _c6*z3 - _c7*z0 + _c7*z2 + _c9*z1 - _c9*z3, 2)/pow(V0, 2);
}

#define MSSLIB_TET_VOLUME_GRADIENT_N_OUT 12

/* tet_volume_gradient: Tetrahedron volume energy k_v/(2 V0^2) (V - V0)^2 (Lloyd et al. App. C.2). Gradient dW/dx [N] (the force is minus this), 12 entries, node by node.
 * Writes out[0..11] = (g0, g1, g2, g3, g4, g5, g6, g7, g8, g9, g10, g11). */
MSSLIB_API void msslib_tet_volume_gradient(double x0, double y0, double z0, double x1, double y1, double z1, double x2, double y2, double z2, double x3, double y3, double z3, double k_v, double V0, double *out)
{
    const double _c0 = y3*z1;
    const double _c1 = y1*z3;
    const double _c2 = y2*z3;
    const double _c3 = y3*z2;
    const double _c4 = _c2 - _c3;
    const double _c5 = y1*z2;
    const double _c6 = y2*z1;
    const double _c7 = _c5 - _c6;
    const double _c8 = (1.0/6.0)*x0;
    const double _c9 = x1*z2;
    const double _c10 = (1.0/6.0)*y0;
    const double _c11 = x1*z3;
    const double _c12 = x1*y2;
    const double _c13 = (1.0/6.0)*z0;
    const double _c14 = (1.0/6.0)*x1;
    const double _c15 = x1*y3;
    const double _c16 = x2*z1;
    const double _c17 = x2*z3;
    const double _c18 = x2*y1;
    const double _c19 = (1.0/6.0)*x2;
    const double _c20 = x2*y3;
    const double _c21 = x3*z1;
    const double _c22 = x3*z2;
    const double _c23 = x3*y1;
    const double _c24 = (1.0/6.0)*x3;
    const double _c25 = x3*y2;
    const double _c26 = (1.0/6.0)*k_v*(V0 - _c0*_c19 + _c0*_c8 + _c1*_c19 - _c1*_c8 + _c10*_c11 + _c10*_c16 - _c10*_c17 - _c10*_c21 + _c10*_c22 - _c10*_c9 + _c12*_c13 - _c13*_c15 - _c13*_c18 + _c13*_c20 + _c13*_c23 - _c13*_c25 - _c14*_c2 + _c14*_c3 + _c2*_c8 - _c24*_c5 + _c24*_c6 - _c3*_c8 + _c5*_c8 - _c6*_c8)/pow(V0, 2);
    const double _c27 = _c17 - _c22;
    const double _c28 = -_c16 + _c9;
    const double _c29 = _c20 - _c25;
    const double _c30 = _c12 - _c18;
    const double _c31 = y0*z2;
    const double _c32 = y2*z0;
    const double _c33 = -y0*z3 + y3*z0;
    const double _c34 = x0*z2;
    const double _c35 = x2*z0;
    const double _c36 = -x0*z3 + x3*z0;
    const double _c37 = x0*y2;
    const double _c38 = x2*y0;
    const double _c39 = -x0*y3 + x3*y0;
    const double _c40 = y0*z1 - y1*z0;
    const double _c41 = x0*z1 - x1*z0;
    const double _c42 = x0*y1 - x1*y0;
    out[0] = _c26*(_c0 - _c1 + _c4 + _c7);
    out[1] = -_c26*(-_c11 + _c21 + _c27 + _c28);
    out[2] = _c26*(-_c15 + _c23 + _c29 + _c30);
    out[3] = -_c26*(_c31 - _c32 + _c33 + _c4);
    out[4] = _c26*(_c27 + _c34 - _c35 + _c36);
    out[5] = -_c26*(_c29 + _c37 - _c38 + _c39);
    out[6] = _c26*(-_c0 + _c1 + _c33 + _c40);
    out[7] = -_c26*(_c11 - _c21 + _c36 + _c41);
    out[8] = _c26*(_c15 - _c23 + _c39 + _c42);
    out[9] = -_c26*(-_c31 + _c32 + _c40 + _c7);
    out[10] = _c26*(_c28 - _c34 + _c35 + _c41);
    out[11] = -_c26*(_c30 - _c37 + _c38 + _c42);
}

#define MSSLIB_TET_VOLUME_HESSIAN_N_OUT 144

/* tet_volume_hessian: Tetrahedron volume energy k_v/(2 V0^2) (V - V0)^2 (Lloyd et al. App. C.2). Hessian [N/m], 12x12 row-major.
 * Writes out[0..143] = (h0, h1, h2, h3, h4, h5, h6, h7, h8, h9, h10, h11, h12, h13, h14, h15, h16, h17, h18, h19, h20, h21, h22, h23, h24, h25, h26, h27, h28, h29, h30, h31, h32, h33, h34, h35, h36, h37, h38, h39, h40, h41, h42, h43, h44, h45, h46, h47, h48, h49, h50, h51, h52, h53, h54, h55, h56, h57, h58, h59, h60, h61, h62, h63, h64, h65, h66, h67, h68, h69, h70, h71, h72, h73, h74, h75, h76, h77, h78, h79, h80, h81, h82, h83, h84, h85, h86, h87, h88, h89, h90, h91, h92, h93, h94, h95, h96, h97, h98, h99, h100, h101, h102, h103, h104, h105, h106, h107, h108, h109, h110, h111, h112, h113, h114, h115, h116, h117, h118, h119, h120, h121, h122, h123, h124, h125, h126, h127, h128, h129, h130, h131, h132, h133, h134, h135, h136, h137, h138, h139, h140, h141, h142, h143). */
MSSLIB_API void msslib_tet_volume_hessian(double x0, double y0, double z0, double x1, double y1, double z1, double x2, double y2, double z2, double x3, double y3, double z3, double k_v, double V0, double *out)
{
    const double _c0 = y3*z1;
    const double _c1 = y1*z3;
    const double _c2 = y2*z3;
    const double _c3 = y3*z2;
    const double _c4 = _c2 - _c3;
    const double _c5 = y1*z2;
    const double _c6 = y2*z1;
    const double _c7 = _c5 - _c6;
    const double _c8 = _c0 - _c1 + _c4 + _c7;
    const double _c9 = (1.0/36.0)*k_v/pow(V0, 2);
    const double _c10 = x3*z1;
    const double _c11 = x1*z3;
    const double _c12 = x2*z3;
    const double _c13 = x3*z2;
    const double _c14 = _c12 - _c13;
    const double _c15 = x1*z2;
    const double _c16 = x2*z1;
    const double _c17 = _c15 - _c16;
    const double _c18 = _c10 - _c11 + _c14 + _c17;
    const double _c19 = _c8*_c9;
    const double _c20 = -_c18*_c19;
    const double _c21 = x3*y1;
    const double _c22 = x1*y3;
    const double _c23 = x2*y3;
    const double _c24 = x3*y2;
    const double _c25 = _c23 - _c24;
    const double _c26 = x1*y2;
    const double _c27 = x2*y1;
    const double _c28 = _c26 - _c27;
    const double _c29 = _c21 - _c22 + _c25 + _c28;
    const double _c30 = _c19*_c29;
    const double _c31 = y0*z2;
    const double _c32 = y2*z0;
    const double _c33 = -y0*z3 + y3*z0;
    const double _c34 = _c31 - _c32 + _c33 + _c4;
    const double _c35 = -_c19*_c34;
    const double _c36 = x0*z2;
    const double _c37 = x2*z0;
    const double _c38 = -x0*z3 + x3*z0;
    const double _c39 = _c14 + _c36 - _c37 + _c38;
    const double _c40 = -z3;
    const double _c41 = 6*V0 + _c0*x0 - _c0*x2 - _c1*x0 + _c1*x2 - _c10*y0 + _c11*y0 - _c12*y0 + _c13*y0 - _c15*y0 + _c16*y0 + _c2*x0 - _c2*x1 + _c21*z0 - _c22*z0 + _c23*z0 - _c24*z0 + _c26*z0 - _c27*z0 - _c3*x0 + _c3*x1 + _c5*x0 - _c5*x3 - _c6*x0 + _c6*x3;
    const double _c42 = _c41*(_c40 + z2);
    const double _c43 = _c9*(_c39*_c8 + _c42);
    const double _c44 = x0*y2;
    const double _c45 = x2*y0;
    const double _c46 = -x0*y3 + x3*y0;
    const double _c47 = _c25 + _c44 - _c45 + _c46;
    const double _c48 = -y3;
    const double _c49 = _c41*(_c48 + y2);
    const double _c50 = -_c9*(_c47*_c8 + _c49);
    const double _c51 = y0*z1 - y1*z0;
    const double _c52 = -_c0 + _c1 + _c33 + _c51;
    const double _c53 = _c19*_c52;
    const double _c54 = x0*z1 - x1*z0;
    const double _c55 = -_c10 + _c11 + _c38 + _c54;
    const double _c56 = _c41*(_c40 + z1);
    const double _c57 = -_c9*(_c55*_c8 + _c56);
    const double _c58 = x0*y1 - x1*y0;
    const double _c59 = -_c21 + _c22 + _c46 + _c58;
    const double _c60 = _c41*(_c48 + y1);
    const double _c61 = _c9*(_c59*_c8 + _c60);
    const double _c62 = -_c31 + _c32 + _c51 + _c7;
    const double _c63 = -_c19*_c62;
    const double _c64 = _c17 - _c36 + _c37 + _c54;
    const double _c65 = -z2;
    const double _c66 = _c41*(_c65 + z1);
    const double _c67 = _c9*(_c64*_c8 + _c66);
    const double _c68 = _c28 - _c44 + _c45 + _c58;
    const double _c69 = -y2;
    const double _c70 = _c41*(_c69 + y1);
    const double _c71 = -_c9*(_c68*_c8 + _c70);
    const double _c72 = _c18*_c9;
    const double _c73 = -_c29*_c72;
    const double _c74 = _c9*(_c18*_c34 - _c42);
    const double _c75 = -_c39*_c72;
    const double _c76 = -x3;
    const double _c77 = _c41*(_c76 + x2);
    const double _c78 = _c9*(_c18*_c47 + _c77);
    const double _c79 = _c9*(-_c18*_c52 + _c56);
    const double _c80 = _c55*_c72;
    const double _c81 = _c41*(_c76 + x1);
    const double _c82 = -_c9*(_c18*_c59 + _c81);
    const double _c83 = _c9*(_c18*_c62 - _c66);
    const double _c84 = -_c64*_c72;
    const double _c85 = -x2;
    const double _c86 = _c41*(_c85 + x1);
    const double _c87 = _c9*(_c18*_c68 + _c86);
    const double _c88 = _c9*(-_c29*_c34 + _c49);
    const double _c89 = _c9*(_c29*_c39 - _c77);
    const double _c90 = _c29*_c9;
    const double _c91 = -_c47*_c90;
    const double _c92 = _c9*(_c29*_c52 - _c60);
    const double _c93 = _c9*(-_c29*_c55 + _c81);
    const double _c94 = _c59*_c90;
    const double _c95 = _c9*(-_c29*_c62 + _c70);
    const double _c96 = _c9*(_c29*_c64 - _c86);
    const double _c97 = -_c68*_c90;
    const double _c98 = _c34*_c9;
    const double _c99 = -_c39*_c98;
    const double _c100 = _c47*_c98;
    const double _c101 = -_c52*_c98;
    const double _c102 = _c41*(_c40 + z0);
    const double _c103 = _c9*(_c102 + _c34*_c55);
    const double _c104 = _c41*(_c48 + y0);
    const double _c105 = -_c9*(_c104 + _c34*_c59);
    const double _c106 = _c62*_c98;
    const double _c107 = _c41*(_c65 + z0);
    const double _c108 = -_c9*(_c107 + _c34*_c64);
    const double _c109 = _c41*(_c69 + y0);
    const double _c110 = _c9*(_c109 + _c34*_c68);
    const double _c111 = _c39*_c9;
    const double _c112 = -_c111*_c47;
    const double _c113 = _c9*(-_c102 + _c39*_c52);
    const double _c114 = -_c111*_c55;
    const double _c115 = _c41*(_c76 + x0);
    const double _c116 = _c9*(_c115 + _c39*_c59);
    const double _c117 = _c9*(_c107 - _c39*_c62);
    const double _c118 = _c111*_c64;
    const double _c119 = _c41*(_c85 + x0);
    const double _c120 = -_c9*(_c119 + _c39*_c68);
    const double _c121 = _c9*(_c104 - _c47*_c52);
    const double _c122 = _c9*(-_c115 + _c47*_c55);
    const double _c123 = _c47*_c9;
    const double _c124 = -_c123*_c59;
    const double _c125 = _c9*(-_c109 + _c47*_c62);
    const double _c126 = _c9*(_c119 - _c47*_c64);
    const double _c127 = _c123*_c68;
    const double _c128 = _c52*_c9;
    const double _c129 = -_c128*_c55;
    const double _c130 = _c128*_c59;
    const double _c131 = -_c128*_c62;
    const double _c132 = _c41*(z0 - z1);
    const double _c133 = _c9*(_c132 + _c52*_c64);
    const double _c134 = _c41*(y0 - y1);
    const double _c135 = -_c9*(_c134 + _c52*_c68);
    const double _c136 = _c55*_c9;
    const double _c137 = -_c136*_c59;
    const double _c138 = _c9*(-_c132 + _c55*_c62);
    const double _c139 = -_c136*_c64;
    const double _c140 = _c41*(x0 - x1);
    const double _c141 = _c9*(_c140 + _c55*_c68);
    const double _c142 = _c9*(_c134 - _c59*_c62);
    const double _c143 = _c9*(-_c140 + _c59*_c64);
    const double _c144 = _c68*_c9;
    const double _c145 = -_c144*_c59;
    const double _c146 = -_c62*_c64*_c9;
    const double _c147 = _c144*_c62;
    const double _c148 = -_c144*_c64;
    out[0] = pow(_c8, 2)*_c9;
    out[1] = _c20;
    out[2] = _c30;
    out[3] = _c35;
    out[4] = _c43;
    out[5] = _c50;
    out[6] = _c53;
    out[7] = _c57;
    out[8] = _c61;
    out[9] = _c63;
    out[10] = _c67;
    out[11] = _c71;
    out[12] = _c20;
    out[13] = pow(_c18, 2)*_c9;
    out[14] = _c73;
    out[15] = _c74;
    out[16] = _c75;
    out[17] = _c78;
    out[18] = _c79;
    out[19] = _c80;
    out[20] = _c82;
    out[21] = _c83;
    out[22] = _c84;
    out[23] = _c87;
    out[24] = _c30;
    out[25] = _c73;
    out[26] = pow(_c29, 2)*_c9;
    out[27] = _c88;
    out[28] = _c89;
    out[29] = _c91;
    out[30] = _c92;
    out[31] = _c93;
    out[32] = _c94;
    out[33] = _c95;
    out[34] = _c96;
    out[35] = _c97;
    out[36] = _c35;
    out[37] = _c74;
    out[38] = _c88;
    out[39] = pow(_c34, 2)*_c9;
    out[40] = _c99;
    out[41] = _c100;
    out[42] = _c101;
    out[43] = _c103;
    out[44] = _c105;
    out[45] = _c106;
    out[46] = _c108;
    out[47] = _c110;
    out[48] = _c43;
    out[49] = _c75;
    out[50] = _c89;
    out[51] = _c99;
    out[52] = pow(_c39, 2)*_c9;
    out[53] = _c112;
    out[54] = _c113;
    out[55] = _c114;
    out[56] = _c116;
    out[57] = _c117;
    out[58] = _c118;
    out[59] = _c120;
    out[60] = _c50;
    out[61] = _c78;
    out[62] = _c91;
    out[63] = _c100;
    out[64] = _c112;
    out[65] = pow(_c47, 2)*_c9;
    out[66] = _c121;
    out[67] = _c122;
    out[68] = _c124;
    out[69] = _c125;
    out[70] = _c126;
    out[71] = _c127;
    out[72] = _c53;
    out[73] = _c79;
    out[74] = _c92;
    out[75] = _c101;
    out[76] = _c113;
    out[77] = _c121;
    out[78] = pow(_c52, 2)*_c9;
    out[79] = _c129;
    out[80] = _c130;
    out[81] = _c131;
    out[82] = _c133;
    out[83] = _c135;
    out[84] = _c57;
    out[85] = _c80;
    out[86] = _c93;
    out[87] = _c103;
    out[88] = _c114;
    out[89] = _c122;
    out[90] = _c129;
    out[91] = pow(_c55, 2)*_c9;
    out[92] = _c137;
    out[93] = _c138;
    out[94] = _c139;
    out[95] = _c141;
    out[96] = _c61;
    out[97] = _c82;
    out[98] = _c94;
    out[99] = _c105;
    out[100] = _c116;
    out[101] = _c124;
    out[102] = _c130;
    out[103] = _c137;
    out[104] = pow(_c59, 2)*_c9;
    out[105] = _c142;
    out[106] = _c143;
    out[107] = _c145;
    out[108] = _c63;
    out[109] = _c83;
    out[110] = _c95;
    out[111] = _c106;
    out[112] = _c117;
    out[113] = _c125;
    out[114] = _c131;
    out[115] = _c138;
    out[116] = _c142;
    out[117] = pow(_c62, 2)*_c9;
    out[118] = _c146;
    out[119] = _c147;
    out[120] = _c67;
    out[121] = _c84;
    out[122] = _c96;
    out[123] = _c108;
    out[124] = _c118;
    out[125] = _c126;
    out[126] = _c133;
    out[127] = _c139;
    out[128] = _c143;
    out[129] = _c146;
    out[130] = pow(_c64, 2)*_c9;
    out[131] = _c148;
    out[132] = _c71;
    out[133] = _c87;
    out[134] = _c97;
    out[135] = _c110;
    out[136] = _c120;
    out[137] = _c127;
    out[138] = _c135;
    out[139] = _c141;
    out[140] = _c145;
    out[141] = _c147;
    out[142] = _c148;
    out[143] = pow(_c68, 2)*_c9;
}

/* hex_volume_energy: Hexahedron volume correction kappa/(2 V0) (V - V0)^2, V from the averaged edge vectors (Golec et al.). Energy [J].
 * Returns energy. */
MSSLIB_API double msslib_hex_volume_energy(double x0, double y0, double z0, double x1, double y1, double z1, double x2, double y2, double z2, double x3, double y3, double z3, double x4, double y4, double z4, double x5, double y5, double z5, double x6, double y6, double z6, double x7, double y7, double z7, double kappa, double V0)
{
    const double _c0 = -z6;
    const double _c1 = _c0 + z0 - z2 + z4;
    const double _c2 = z3 - z5;
    const double _c3 = -x6;
    const double _c4 = _c3 + x0 + x1 - x7;
    const double _c5 = x3 - x5;
    const double _c6 = _c4 + _c5 + x2 - x4;
    const double _c7 = -y6;
    const double _c8 = _c7 + y0 + y1 - y7;
    const double _c9 = -y2 + y4;
    const double _c10 = -_c8 - _c9 + y3 - y5;
    const double _c11 = -x2 + x4;
    const double _c12 = _c11 + _c4 - x3 + x5;
    const double _c13 = y3 - y5;
    const double _c14 = -_c13 - _c8 - y2 + y4;
    const double _c15 = z1 - z7;
    const double _c16 = _c0 + _c15 + _c2 + z0 + z2 - z4;
    const double _c17 = _c1 + _c15 - z3 + z5;
    return (1.0/2.0)*kappa*pow(V0 - 1.0/64.0*(_c10*_c16 - _c14*_c17)*(_c11 + _c3 + _c5 + x0 - x1 + x7) - 1.0/64.0*(-_c10*_c6 + _c12*_c14)*(_c1 + _c2 - z1 + z7) + (1.0/64.0)*(-_c12*_c16 + _c17*_c6)*(_c13 + _c7 + _c9 + y0 - y1 + y7), 2)/V0;
}

#define MSSLIB_HEX_VOLUME_GRADIENT_N_OUT 24

/* hex_volume_gradient: Hexahedron volume correction kappa/(2 V0) (V - V0)^2, V from the averaged edge vectors (Golec et al.). Gradient dW/dx [N] (the force is minus this), 24 entries, node by node.
 * Writes out[0..23] = (g0, g1, g2, g3, g4, g5, g6, g7, g8, g9, g10, g11, g12, g13, g14, g15, g16, g17, g18, g19, g20, g21, g22, g23). */
MSSLIB_API void msslib_hex_volume_gradient(double x0, double y0, double z0, double x1, double y1, double z1, double x2, double y2, double z2, double x3, double y3, double z3, double x4, double y4, double z4, double x5, double y5, double z5, double x6, double y6, double z6, double x7, double y7, double z7, double kappa, double V0, double *out)
{
    const double _c0 = y3 - y5;
    const double _c1 = y0 - y6;
    const double _c2 = -y2 + y4;
    const double _c3 = _c0 + _c1 + _c2 - y1 + y7;
    const double _c4 = z3 - z5;
    const double _c5 = _c4 + z2 - z4;
    const double _c6 = 2*_c5;
    const double _c7 = _c0 + y2 - y4;
    const double _c8 = z0 - z6;
    const double _c9 = -z2 + z4;
    const double _c10 = _c4 + _c8 + _c9 - z1 + z7;
    const double _c11 = 2*_c10;
    const double _c12 = _c11*_c7 - _c3*_c6;
    const double _c13 = _c1 + y1 - y7;
    const double _c14 = _c13 + _c2 - y3 + y5;
    const double _c15 = _c8 + z1 - z7;
    const double _c16 = _c15 + _c5;
    const double _c17 = _c14*_c16;
    const double _c18 = _c13 + _c7;
    const double _c19 = _c15 + _c9 - z3 + z5;
    const double _c20 = _c18*_c19;
    const double _c21 = _c17 - _c20;
    const double _c22 = x3 - x5;
    const double _c23 = _c22 + x2 - x4;
    const double _c24 = x0 - x6;
    const double _c25 = _c24 + x1 - x7;
    const double _c26 = _c23 + _c25;
    const double _c27 = -_c14;
    const double _c28 = -x2 + x4;
    const double _c29 = _c25 + _c28 - x3 + x5;
    const double _c30 = -_c18;
    const double _c31 = _c16*_c29;
    const double _c32 = _c19*_c26;
    const double _c33 = _c31 - _c32;
    const double _c34 = _c22 + _c24 + _c28 - x1 + x7;
    const double _c35 = (1.0/64.0)*kappa*(V0 - 1.0/64.0*_c10*(-_c26*_c27 + _c29*_c30) - 1.0/64.0*_c3*_c33 - 1.0/64.0*_c34*(_c16*_c27 - _c19*_c30))/V0;
    const double _c36 = _c35*(_c12 + _c21);
    const double _c37 = _c11*_c23 - _c34*_c6;
    const double _c38 = _c35*(_c33 + _c37);
    const double _c39 = 2*_c34;
    const double _c40 = 2*_c3;
    const double _c41 = _c23*_c40 - _c39*_c7;
    const double _c42 = _c18*_c29;
    const double _c43 = _c14*_c26;
    const double _c44 = _c42 - _c43;
    const double _c45 = _c35*(_c41 + _c44);
    const double _c46 = -_c17 + _c20;
    const double _c47 = _c35*(_c12 + _c46);
    const double _c48 = -_c31 + _c32;
    const double _c49 = _c35*(_c37 + _c48);
    const double _c50 = -_c42 + _c43;
    const double _c51 = _c35*(_c41 + _c50);
    const double _c52 = _c11*_c13 - _c15*_c40;
    const double _c53 = _c35*(_c21 + _c52);
    const double _c54 = _c11*_c25 - _c15*_c39;
    const double _c55 = _c35*(_c33 + _c54);
    const double _c56 = -_c13*_c39 + _c25*_c40;
    const double _c57 = _c35*(_c44 + _c56);
    const double _c58 = _c35*(_c46 + _c52);
    const double _c59 = _c35*(_c48 + _c54);
    const double _c60 = _c35*(_c50 + _c56);
    out[0] = _c36;
    out[1] = -_c38;
    out[2] = _c45;
    out[3] = _c47;
    out[4] = -_c49;
    out[5] = _c51;
    out[6] = -_c53;
    out[7] = _c55;
    out[8] = -_c57;
    out[9] = -_c58;
    out[10] = _c59;
    out[11] = -_c60;
    out[12] = _c53;
    out[13] = -_c55;
    out[14] = _c57;
    out[15] = _c58;
    out[16] = -_c59;
    out[17] = _c60;
    out[18] = -_c36;
    out[19] = _c38;
    out[20] = -_c45;
    out[21] = -_c47;
    out[22] = _c49;
    out[23] = -_c51;
}

#define MSSLIB_HEX_VOLUME_HESSIAN_N_OUT 576

/* hex_volume_hessian: Hexahedron volume correction kappa/(2 V0) (V - V0)^2, V from the averaged edge vectors (Golec et al.). Hessian [N/m], 24x24 row-major.
 * Writes out[0..575] = (h0, h1, h2, h3, h4, h5, h6, h7, h8, h9, h10, h11, h12, h13, h14, h15, h16, h17, h18, h19, h20, h21, h22, h23, h24, h25, h26, h27, h28, h29, h30, h31, h32, h33, h34, h35, h36, h37, h38, h39, h40, h41, h42, h43, h44, h45, h46, h47, h48, h49, h50, h51, h52, h53, h54, h55, h56, h57, h58, h59, h60, h61, h62, h63, h64, h65, h66, h67, h68, h69, h70, h71, h72, h73, h74, h75, h76, h77, h78, h79, h80, h81, h82, h83, h84, h85, h86, h87, h88, h89, h90, h91, h92, h93, h94, h95, h96, h97, h98, h99, h100, h101, h102, h103, h104, h105, h106, h107, h108, h109, h110, h111, h112, h113, h114, h115, h116, h117, h118, h119, h120, h121, h122, h123, h124, h125, h126, h127, h128, h129, h130, h131, h132, h133, h134, h135, h136, h137, h138, h139, h140, h141, h142, h143, h144, h145, h146, h147, h148, h149, h150, h151, h152, h153, h154, h155, h156, h157, h158, h159, h160, h161, h162, h163, h164, h165, h166, h167, h168, h169, h170, h171, h172, h173, h174, h175, h176, h177, h178, h179, h180, h181, h182, h183, h184, h185, h186, h187, h188, h189, h190, h191, h192, h193, h194, h195, h196, h197, h198, h199, h200, h201, h202, h203, h204, h205, h206, h207, h208, h209, h210, h211, h212, h213, h214, h215, h216, h217, h218, h219, h220, h221, h222, h223, h224, h225, h226, h227, h228, h229, h230, h231, h232, h233, h234, h235, h236, h237, h238, h239, h240, h241, h242, h243, h244, h245, h246, h247, h248, h249, h250, h251, h252, h253, h254, h255, h256, h257, h258, h259, h260, h261, h262, h263, h264, h265, h266, h267, h268, h269, h270, h271, h272, h273, h274, h275, h276, h277, h278, h279, h280, h281, h282, h283, h284, h285, h286, h287, h288, h289, h290, h291, h292, h293, h294, h295, h296, h297, h298, h299, h300, h301, h302, h303, h304, h305, h306, h307, h308, h309, h310, h311, h312, h313, h314, h315, h316, h317, h318, h319, h320, h321, h322, h323, h324, h325, h326, h327, h328, h329, h330, h331, h332, h333, h334, h335, h336, h337, h338, h339, h340, h341, h342, h343, h344, h345, h346, h347, h348, h349, h350, h351, h352, h353, h354, h355, h356, h357, h358, h359, h360, h361, h362, h363, h364, h365, h366, h367, h368, h369, h370, h371, h372, h373, h374, h375, h376, h377, h378, h379, h380, h381, h382, h383, h384, h385, h386, h387, h388, h389, h390, h391, h392, h393, h394, h395, h396, h397, h398, h399, h400, h401, h402, h403, h404, h405, h406, h407, h408, h409, h410, h411, h412, h413, h414, h415, h416, h417, h418, h419, h420, h421, h422, h423, h424, h425, h426, h427, h428, h429, h430, h431, h432, h433, h434, h435, h436, h437, h438, h439, h440, h441, h442, h443, h444, h445, h446, h447, h448, h449, h450, h451, h452, h453, h454, h455, h456, h457, h458, h459, h460, h461, h462, h463, h464, h465, h466, h467, h468, h469, h470, h471, h472, h473, h474, h475, h476, h477, h478, h479, h480, h481, h482, h483, h484, h485, h486, h487, h488, h489, h490, h491, h492, h493, h494, h495, h496, h497, h498, h499, h500, h501, h502, h503, h504, h505, h506, h507, h508, h509, h510, h511, h512, h513, h514, h515, h516, h517, h518, h519, h520, h521, h522, h523, h524, h525, h526, h527, h528, h529, h530, h531, h532, h533, h534, h535, h536, h537, h538, h539, h540, h541, h542, h543, h544, h545, h546, h547, h548, h549, h550, h551, h552, h553, h554, h555, h556, h557, h558, h559, h560, h561, h562, h563, h564, h565, h566, h567, h568, h569, h570, h571, h572, h573, h574, h575). */
MSSLIB_API void msslib_hex_volume_hessian(double x0, double y0, double z0, double x1, double y1, double z1, double x2, double y2, double z2, double x3, double y3, double z3, double x4, double y4, double z4, double x5, double y5, double z5, double x6, double y6, double z6, double x7, double y7, double z7, double kappa, double V0, double *out)
{
    const double _c0 = y3 - y5;
    const double _c1 = y0 - y6;
    const double _c2 = _c0 + _c1;
    const double _c3 = -y2 + y4;
    const double _c4 = _c2 + _c3 - y1 + y7;
    const double _c5 = z2 - z4;
    const double _c6 = z3 - z5;
    const double _c7 = _c5 + _c6;
    const double _c8 = 2*_c7;
    const double _c9 = y2 - y4;
    const double _c10 = _c0 + _c9;
    const double _c11 = z0 - z6;
    const double _c12 = _c11 + _c6;
    const double _c13 = -z2 + z4;
    const double _c14 = _c12 + _c13 - z1 + z7;
    const double _c15 = 2*_c14;
    const double _c16 = _c10*_c15 - _c4*_c8;
    const double _c17 = y1 - y7;
    const double _c18 = _c1 + _c17;
    const double _c19 = -y3 + y5;
    const double _c20 = _c18 + _c19 + _c3;
    const double _c21 = z1 - z7;
    const double _c22 = _c11 + _c21;
    const double _c23 = _c22 + _c7;
    const double _c24 = _c20*_c23;
    const double _c25 = _c10 + _c18;
    const double _c26 = -z3 + z5;
    const double _c27 = _c13 + _c22 + _c26;
    const double _c28 = _c25*_c27;
    const double _c29 = _c24 - _c28;
    const double _c30 = _c16 + _c29;
    const double _c31 = (1.0/4096.0)*kappa/V0;
    const double _c32 = pow(_c30, 2)*_c31;
    const double _c33 = x1 - x7;
    const double _c34 = x0 - x6;
    const double _c35 = _c33 + _c34;
    const double _c36 = -x3 + x5;
    const double _c37 = -x2 + x4;
    const double _c38 = _c35 + _c36 + _c37;
    const double _c39 = _c23*_c38;
    const double _c40 = x2 - x4;
    const double _c41 = x3 - x5;
    const double _c42 = _c40 + _c41;
    const double _c43 = _c35 + _c42;
    const double _c44 = _c27*_c43;
    const double _c45 = _c39 - _c44;
    const double _c46 = _c34 + _c41;
    const double _c47 = _c37 + _c46 - x1 + x7;
    const double _c48 = _c15*_c42 - _c47*_c8;
    const double _c49 = _c45 + _c48;
    const double _c50 = _c30*_c31;
    const double _c51 = _c49*_c50;
    const double _c52 = -_c51;
    const double _c53 = 2*_c47;
    const double _c54 = 2*_c4;
    const double _c55 = -_c10*_c53 + _c42*_c54;
    const double _c56 = _c25*_c38;
    const double _c57 = _c20*_c43;
    const double _c58 = _c56 - _c57;
    const double _c59 = _c55 + _c58;
    const double _c60 = _c50*_c59;
    const double _c61 = -_c24 + _c28;
    const double _c62 = _c16 + _c61;
    const double _c63 = _c50*_c62;
    const double _c64 = -_c39 + _c44;
    const double _c65 = _c48 + _c64;
    const double _c66 = -_c30;
    const double _c67 = -_c20;
    const double _c68 = -_c25;
    const double _c69 = 64*V0 - _c14*(_c38*_c68 - _c43*_c67) - _c4*_c45 - _c47*(_c23*_c67 - _c27*_c68);
    const double _c70 = -4*_c69;
    const double _c71 = _c7*_c70;
    const double _c72 = _c31*(_c65*_c66 - _c71);
    const double _c73 = -_c56 + _c57;
    const double _c74 = _c55 + _c73;
    const double _c75 = 4*_c69;
    const double _c76 = _c10*_c75;
    const double _c77 = _c31*(_c30*_c74 - _c76);
    const double _c78 = _c15*_c18 - _c22*_c54;
    const double _c79 = _c29 + _c78;
    const double _c80 = _c50*_c79;
    const double _c81 = -_c80;
    const double _c82 = _c15*_c35 - _c22*_c53;
    const double _c83 = _c45 + _c82;
    const double _c84 = _c21 + _c26;
    const double _c85 = _c75*_c84;
    const double _c86 = _c31*(_c30*_c83 - _c85);
    const double _c87 = -_c18*_c53 + _c35*_c54;
    const double _c88 = _c58 + _c87;
    const double _c89 = _c17 + _c19;
    const double _c90 = _c70*_c89;
    const double _c91 = _c31*(_c66*_c88 - _c90);
    const double _c92 = _c61 + _c78;
    const double _c93 = _c50*_c92;
    const double _c94 = -_c93;
    const double _c95 = _c64 + _c82;
    const double _c96 = _c21 + _c5;
    const double _c97 = _c75*_c96;
    const double _c98 = _c31*(_c30*_c95 - _c97);
    const double _c99 = _c73 + _c87;
    const double _c100 = _c17 + _c9;
    const double _c101 = _c100*_c70;
    const double _c102 = _c31*(-_c101 + _c66*_c99);
    const double _c103 = _c70*_c84;
    const double _c104 = _c31*(-_c103 + _c66*_c83);
    const double _c105 = _c75*_c89;
    const double _c106 = _c31*(-_c105 + _c30*_c88);
    const double _c107 = _c70*_c96;
    const double _c108 = _c31*(-_c107 + _c66*_c95);
    const double _c109 = _c100*_c75;
    const double _c110 = _c31*(-_c109 + _c30*_c99);
    const double _c111 = -_c32;
    const double _c112 = -_c60;
    const double _c113 = -_c63;
    const double _c114 = _c7*_c75;
    const double _c115 = _c31*(-_c114 + _c30*_c65);
    const double _c116 = _c10*_c70;
    const double _c117 = _c31*(-_c116 + _c66*_c74);
    const double _c118 = _c31*pow(_c49, 2);
    const double _c119 = _c31*_c49;
    const double _c120 = _c119*_c59;
    const double _c121 = -_c120;
    const double _c122 = -_c31*(_c114 + _c49*_c62);
    const double _c123 = _c119*_c65;
    const double _c124 = -_c74;
    const double _c125 = _c42*_c70;
    const double _c126 = _c31*(_c124*_c49 - _c125);
    const double _c127 = _c31*(-_c103 + _c49*_c79);
    const double _c128 = _c119*_c83;
    const double _c129 = -_c128;
    const double _c130 = _c33 + _c36;
    const double _c131 = _c130*_c75;
    const double _c132 = _c31*(-_c131 + _c49*_c88);
    const double _c133 = _c31*(-_c107 + _c49*_c92);
    const double _c134 = _c119*_c95;
    const double _c135 = -_c134;
    const double _c136 = _c33 + _c40;
    const double _c137 = _c136*_c75;
    const double _c138 = _c31*(-_c137 + _c49*_c99);
    const double _c139 = -_c31*(_c49*_c79 + _c85);
    const double _c140 = -_c88;
    const double _c141 = _c130*_c70;
    const double _c142 = _c31*(_c140*_c49 - _c141);
    const double _c143 = -_c31*(_c49*_c92 + _c97);
    const double _c144 = -_c99;
    const double _c145 = _c136*_c70;
    const double _c146 = _c31*(_c144*_c49 - _c145);
    const double _c147 = -_c118;
    const double _c148 = _c31*(_c49*_c62 - _c71);
    const double _c149 = -_c123;
    const double _c150 = _c42*_c75;
    const double _c151 = _c31*(-_c150 + _c49*_c74);
    const double _c152 = _c31*pow(_c59, 2);
    const double _c153 = -_c59;
    const double _c154 = -_c62;
    const double _c155 = _c31*(-_c116 + _c153*_c154);
    const double _c156 = -_c31*(_c150 + _c59*_c65);
    const double _c157 = _c31*_c59;
    const double _c158 = _c157*_c74;
    const double _c159 = -_c31*(_c105 + _c59*_c79);
    const double _c160 = -_c83;
    const double _c161 = _c31*(-_c141 + _c153*_c160);
    const double _c162 = _c157*_c88;
    const double _c163 = -_c162;
    const double _c164 = -_c31*(_c109 + _c59*_c92);
    const double _c165 = -_c95;
    const double _c166 = _c31*(-_c145 + _c153*_c165);
    const double _c167 = _c157*_c99;
    const double _c168 = -_c167;
    const double _c169 = -_c79;
    const double _c170 = _c31*(_c153*_c169 - _c90);
    const double _c171 = -_c31*(_c131 + _c59*_c83);
    const double _c172 = -_c92;
    const double _c173 = _c31*(-_c101 + _c153*_c172);
    const double _c174 = -_c31*(_c137 + _c59*_c95);
    const double _c175 = -_c152;
    const double _c176 = -_c31*(_c59*_c62 + _c76);
    const double _c177 = -_c65;
    const double _c178 = _c31*(-_c125 + _c153*_c177);
    const double _c179 = -_c158;
    const double _c180 = _c31*pow(_c62, 2);
    const double _c181 = _c31*_c62;
    const double _c182 = _c181*_c65;
    const double _c183 = -_c182;
    const double _c184 = _c181*_c74;
    const double _c185 = _c181*_c79;
    const double _c186 = -_c185;
    const double _c187 = _c12*_c70;
    const double _c188 = _c31*(_c154*_c160 - _c187);
    const double _c189 = _c2*_c75;
    const double _c190 = -_c31*(_c189 + _c62*_c88);
    const double _c191 = _c181*_c92;
    const double _c192 = -_c191;
    const double _c193 = _c11 + _c13;
    const double _c194 = _c193*_c70;
    const double _c195 = _c31*(_c154*_c165 - _c194);
    const double _c196 = _c1 + _c3;
    const double _c197 = _c196*_c75;
    const double _c198 = -_c31*(_c197 + _c62*_c99);
    const double _c199 = _c12*_c75;
    const double _c200 = -_c31*(_c199 + _c62*_c83);
    const double _c201 = _c2*_c70;
    const double _c202 = _c31*(_c140*_c154 - _c201);
    const double _c203 = _c193*_c75;
    const double _c204 = -_c31*(_c203 + _c62*_c95);
    const double _c205 = _c196*_c70;
    const double _c206 = _c31*(_c144*_c154 - _c205);
    const double _c207 = -_c49;
    const double _c208 = _c31*(_c154*_c207 - _c71);
    const double _c209 = -_c180;
    const double _c210 = -_c184;
    const double _c211 = _c31*pow(_c65, 2);
    const double _c212 = _c31*_c65;
    const double _c213 = _c212*_c74;
    const double _c214 = -_c213;
    const double _c215 = _c31*(-_c199 + _c65*_c79);
    const double _c216 = _c212*_c83;
    const double _c217 = -_c216;
    const double _c218 = _c46*_c70;
    const double _c219 = _c31*(-_c218 + _c65*_c88);
    const double _c220 = _c31*(-_c203 + _c65*_c92);
    const double _c221 = _c212*_c95;
    const double _c222 = -_c221;
    const double _c223 = _c34 + _c37;
    const double _c224 = _c223*_c70;
    const double _c225 = _c31*(-_c224 + _c65*_c99);
    const double _c226 = _c31*(_c169*_c65 - _c187);
    const double _c227 = _c46*_c75;
    const double _c228 = -_c31*(_c227 + _c65*_c88);
    const double _c229 = _c31*(_c172*_c65 - _c194);
    const double _c230 = _c223*_c75;
    const double _c231 = -_c31*(_c230 + _c65*_c99);
    const double _c232 = _c31*(-_c125 + _c59*_c65);
    const double _c233 = -_c211;
    const double _c234 = _c31*pow(_c74, 2);
    const double _c235 = _c31*(_c124*_c79 - _c201);
    const double _c236 = _c31*(-_c227 + _c74*_c83);
    const double _c237 = _c31*_c74;
    const double _c238 = _c237*_c88;
    const double _c239 = -_c238;
    const double _c240 = _c31*(_c124*_c92 - _c205);
    const double _c241 = _c31*(-_c230 + _c74*_c95);
    const double _c242 = _c237*_c99;
    const double _c243 = -_c242;
    const double _c244 = _c31*(-_c189 + _c74*_c79);
    const double _c245 = _c31*(_c124*_c83 - _c218);
    const double _c246 = _c31*(-_c197 + _c74*_c92);
    const double _c247 = _c31*(_c124*_c95 - _c224);
    const double _c248 = _c31*(-_c116 + _c124*_c30);
    const double _c249 = -_c234;
    const double _c250 = _c31*pow(_c79, 2);
    const double _c251 = _c31*_c79;
    const double _c252 = _c251*_c83;
    const double _c253 = -_c252;
    const double _c254 = _c251*_c88;
    const double _c255 = _c251*_c92;
    const double _c256 = _c22*_c70;
    const double _c257 = _c31*(_c165*_c79 - _c256);
    const double _c258 = _c18*_c75;
    const double _c259 = _c31*(-_c258 + _c79*_c99);
    const double _c260 = -_c250;
    const double _c261 = -_c254;
    const double _c262 = -_c255;
    const double _c263 = _c22*_c75;
    const double _c264 = _c31*(-_c263 + _c79*_c95);
    const double _c265 = _c18*_c70;
    const double _c266 = _c31*(_c144*_c79 - _c265);
    const double _c267 = _c31*(_c59*_c79 - _c90);
    const double _c268 = _c31*(_c177*_c79 - _c187);
    const double _c269 = _c31*pow(_c83, 2);
    const double _c270 = _c31*_c83;
    const double _c271 = _c270*_c88;
    const double _c272 = -_c271;
    const double _c273 = -_c31*(_c263 + _c83*_c92);
    const double _c274 = _c270*_c95;
    const double _c275 = _c35*_c70;
    const double _c276 = _c31*(_c160*_c99 - _c275);
    const double _c277 = -_c269;
    const double _c278 = _c31*(_c160*_c172 - _c256);
    const double _c279 = -_c274;
    const double _c280 = _c35*_c75;
    const double _c281 = _c31*(-_c280 + _c83*_c99);
    const double _c282 = _c31*(-_c103 + _c160*_c30);
    const double _c283 = _c31*(_c160*_c74 - _c218);
    const double _c284 = _c31*pow(_c88, 2);
    const double _c285 = _c31*(-_c265 + _c88*_c92);
    const double _c286 = -_c31*(_c280 + _c88*_c95);
    const double _c287 = _c31*_c99;
    const double _c288 = _c287*_c88;
    const double _c289 = -_c284;
    const double _c290 = -_c31*(_c258 + _c88*_c92);
    const double _c291 = _c31*(-_c275 + _c88*_c95);
    const double _c292 = -_c288;
    const double _c293 = _c31*(-_c141 + _c207*_c88);
    const double _c294 = _c31*(-_c201 + _c62*_c88);
    const double _c295 = _c31*pow(_c92, 2);
    const double _c296 = _c31*_c92*_c95;
    const double _c297 = -_c296;
    const double _c298 = _c287*_c92;
    const double _c299 = _c31*(-_c256 + _c83*_c92);
    const double _c300 = -_c295;
    const double _c301 = -_c298;
    const double _c302 = _c31*(-_c101 + _c59*_c92);
    const double _c303 = _c31*(_c177*_c92 - _c194);
    const double _c304 = _c31*pow(_c95, 2);
    const double _c305 = _c287*_c95;
    const double _c306 = -_c305;
    const double _c307 = _c31*(_c140*_c165 - _c275);
    const double _c308 = -_c304;
    const double _c309 = _c31*(-_c107 + _c165*_c30);
    const double _c310 = _c31*(_c165*_c74 - _c224);
    const double _c311 = _c31*pow(_c99, 2);
    const double _c312 = _c31*(_c169*_c99 - _c265);
    const double _c313 = -_c311;
    const double _c314 = _c31*(-_c145 + _c207*_c99);
    const double _c315 = _c31*(-_c205 + _c62*_c99);
    const double _c316 = _c31*(_c169*_c95 - _c256);
    const double _c317 = _c31*(-_c103 + _c169*_c207);
    const double _c318 = _c31*(_c169*_c74 - _c201);
    const double _c319 = _c31*(_c144*_c83 - _c275);
    const double _c320 = _c31*(-_c141 + _c59*_c83);
    const double _c321 = _c31*(-_c187 + _c62*_c83);
    const double _c322 = _c31*(_c140*_c172 - _c265);
    const double _c323 = _c31*(_c140*_c30 - _c90);
    const double _c324 = _c31*(_c140*_c177 - _c218);
    const double _c325 = _c31*(-_c107 + _c172*_c207);
    const double _c326 = _c31*(_c172*_c74 - _c205);
    const double _c327 = _c31*(-_c145 + _c59*_c95);
    const double _c328 = _c31*(-_c194 + _c62*_c95);
    const double _c329 = _c31*(-_c101 + _c144*_c30);
    const double _c330 = _c31*(_c144*_c177 - _c224);
    const double _c331 = _c31*(_c177*_c30 - _c71);
    const double _c332 = _c31*(-_c125 + _c207*_c74);
    const double _c333 = _c31*(-_c116 + _c59*_c62);
    out[0] = _c32;
    out[1] = _c52;
    out[2] = _c60;
    out[3] = _c63;
    out[4] = _c72;
    out[5] = _c77;
    out[6] = _c81;
    out[7] = _c86;
    out[8] = _c91;
    out[9] = _c94;
    out[10] = _c98;
    out[11] = _c102;
    out[12] = _c80;
    out[13] = _c104;
    out[14] = _c106;
    out[15] = _c93;
    out[16] = _c108;
    out[17] = _c110;
    out[18] = _c111;
    out[19] = _c51;
    out[20] = _c112;
    out[21] = _c113;
    out[22] = _c115;
    out[23] = _c117;
    out[24] = _c52;
    out[25] = _c118;
    out[26] = _c121;
    out[27] = _c122;
    out[28] = _c123;
    out[29] = _c126;
    out[30] = _c127;
    out[31] = _c129;
    out[32] = _c132;
    out[33] = _c133;
    out[34] = _c135;
    out[35] = _c138;
    out[36] = _c139;
    out[37] = _c128;
    out[38] = _c142;
    out[39] = _c143;
    out[40] = _c134;
    out[41] = _c146;
    out[42] = _c51;
    out[43] = _c147;
    out[44] = _c120;
    out[45] = _c148;
    out[46] = _c149;
    out[47] = _c151;
    out[48] = _c60;
    out[49] = _c121;
    out[50] = _c152;
    out[51] = _c155;
    out[52] = _c156;
    out[53] = _c158;
    out[54] = _c159;
    out[55] = _c161;
    out[56] = _c163;
    out[57] = _c164;
    out[58] = _c166;
    out[59] = _c168;
    out[60] = _c170;
    out[61] = _c171;
    out[62] = _c162;
    out[63] = _c173;
    out[64] = _c174;
    out[65] = _c167;
    out[66] = _c112;
    out[67] = _c120;
    out[68] = _c175;
    out[69] = _c176;
    out[70] = _c178;
    out[71] = _c179;
    out[72] = _c63;
    out[73] = _c122;
    out[74] = _c155;
    out[75] = _c180;
    out[76] = _c183;
    out[77] = _c184;
    out[78] = _c186;
    out[79] = _c188;
    out[80] = _c190;
    out[81] = _c192;
    out[82] = _c195;
    out[83] = _c198;
    out[84] = _c185;
    out[85] = _c200;
    out[86] = _c202;
    out[87] = _c191;
    out[88] = _c204;
    out[89] = _c206;
    out[90] = _c113;
    out[91] = _c208;
    out[92] = _c176;
    out[93] = _c209;
    out[94] = _c182;
    out[95] = _c210;
    out[96] = _c72;
    out[97] = _c123;
    out[98] = _c156;
    out[99] = _c183;
    out[100] = _c211;
    out[101] = _c214;
    out[102] = _c215;
    out[103] = _c217;
    out[104] = _c219;
    out[105] = _c220;
    out[106] = _c222;
    out[107] = _c225;
    out[108] = _c226;
    out[109] = _c216;
    out[110] = _c228;
    out[111] = _c229;
    out[112] = _c221;
    out[113] = _c231;
    out[114] = _c115;
    out[115] = _c149;
    out[116] = _c232;
    out[117] = _c182;
    out[118] = _c233;
    out[119] = _c213;
    out[120] = _c77;
    out[121] = _c126;
    out[122] = _c158;
    out[123] = _c184;
    out[124] = _c214;
    out[125] = _c234;
    out[126] = _c235;
    out[127] = _c236;
    out[128] = _c239;
    out[129] = _c240;
    out[130] = _c241;
    out[131] = _c243;
    out[132] = _c244;
    out[133] = _c245;
    out[134] = _c238;
    out[135] = _c246;
    out[136] = _c247;
    out[137] = _c242;
    out[138] = _c248;
    out[139] = _c151;
    out[140] = _c179;
    out[141] = _c210;
    out[142] = _c213;
    out[143] = _c249;
    out[144] = _c81;
    out[145] = _c127;
    out[146] = _c159;
    out[147] = _c186;
    out[148] = _c215;
    out[149] = _c235;
    out[150] = _c250;
    out[151] = _c253;
    out[152] = _c254;
    out[153] = _c255;
    out[154] = _c257;
    out[155] = _c259;
    out[156] = _c260;
    out[157] = _c252;
    out[158] = _c261;
    out[159] = _c262;
    out[160] = _c264;
    out[161] = _c266;
    out[162] = _c80;
    out[163] = _c139;
    out[164] = _c267;
    out[165] = _c185;
    out[166] = _c268;
    out[167] = _c244;
    out[168] = _c86;
    out[169] = _c129;
    out[170] = _c161;
    out[171] = _c188;
    out[172] = _c217;
    out[173] = _c236;
    out[174] = _c253;
    out[175] = _c269;
    out[176] = _c272;
    out[177] = _c273;
    out[178] = _c274;
    out[179] = _c276;
    out[180] = _c252;
    out[181] = _c277;
    out[182] = _c271;
    out[183] = _c278;
    out[184] = _c279;
    out[185] = _c281;
    out[186] = _c282;
    out[187] = _c128;
    out[188] = _c171;
    out[189] = _c200;
    out[190] = _c216;
    out[191] = _c283;
    out[192] = _c91;
    out[193] = _c132;
    out[194] = _c163;
    out[195] = _c190;
    out[196] = _c219;
    out[197] = _c239;
    out[198] = _c254;
    out[199] = _c272;
    out[200] = _c284;
    out[201] = _c285;
    out[202] = _c286;
    out[203] = _c288;
    out[204] = _c261;
    out[205] = _c271;
    out[206] = _c289;
    out[207] = _c290;
    out[208] = _c291;
    out[209] = _c292;
    out[210] = _c106;
    out[211] = _c293;
    out[212] = _c162;
    out[213] = _c294;
    out[214] = _c228;
    out[215] = _c238;
    out[216] = _c94;
    out[217] = _c133;
    out[218] = _c164;
    out[219] = _c192;
    out[220] = _c220;
    out[221] = _c240;
    out[222] = _c255;
    out[223] = _c273;
    out[224] = _c285;
    out[225] = _c295;
    out[226] = _c297;
    out[227] = _c298;
    out[228] = _c262;
    out[229] = _c299;
    out[230] = _c290;
    out[231] = _c300;
    out[232] = _c296;
    out[233] = _c301;
    out[234] = _c93;
    out[235] = _c143;
    out[236] = _c302;
    out[237] = _c191;
    out[238] = _c303;
    out[239] = _c246;
    out[240] = _c98;
    out[241] = _c135;
    out[242] = _c166;
    out[243] = _c195;
    out[244] = _c222;
    out[245] = _c241;
    out[246] = _c257;
    out[247] = _c274;
    out[248] = _c286;
    out[249] = _c297;
    out[250] = _c304;
    out[251] = _c306;
    out[252] = _c264;
    out[253] = _c279;
    out[254] = _c307;
    out[255] = _c296;
    out[256] = _c308;
    out[257] = _c305;
    out[258] = _c309;
    out[259] = _c134;
    out[260] = _c174;
    out[261] = _c204;
    out[262] = _c221;
    out[263] = _c310;
    out[264] = _c102;
    out[265] = _c138;
    out[266] = _c168;
    out[267] = _c198;
    out[268] = _c225;
    out[269] = _c243;
    out[270] = _c259;
    out[271] = _c276;
    out[272] = _c288;
    out[273] = _c298;
    out[274] = _c306;
    out[275] = _c311;
    out[276] = _c312;
    out[277] = _c281;
    out[278] = _c292;
    out[279] = _c301;
    out[280] = _c305;
    out[281] = _c313;
    out[282] = _c110;
    out[283] = _c314;
    out[284] = _c167;
    out[285] = _c315;
    out[286] = _c231;
    out[287] = _c242;
    out[288] = _c80;
    out[289] = _c139;
    out[290] = _c170;
    out[291] = _c185;
    out[292] = _c226;
    out[293] = _c244;
    out[294] = _c260;
    out[295] = _c252;
    out[296] = _c261;
    out[297] = _c262;
    out[298] = _c264;
    out[299] = _c312;
    out[300] = _c250;
    out[301] = _c253;
    out[302] = _c254;
    out[303] = _c255;
    out[304] = _c316;
    out[305] = _c259;
    out[306] = _c81;
    out[307] = _c317;
    out[308] = _c159;
    out[309] = _c186;
    out[310] = _c215;
    out[311] = _c318;
    out[312] = _c104;
    out[313] = _c128;
    out[314] = _c171;
    out[315] = _c200;
    out[316] = _c216;
    out[317] = _c245;
    out[318] = _c252;
    out[319] = _c277;
    out[320] = _c271;
    out[321] = _c299;
    out[322] = _c279;
    out[323] = _c281;
    out[324] = _c253;
    out[325] = _c269;
    out[326] = _c272;
    out[327] = _c273;
    out[328] = _c274;
    out[329] = _c319;
    out[330] = _c86;
    out[331] = _c129;
    out[332] = _c320;
    out[333] = _c321;
    out[334] = _c217;
    out[335] = _c236;
    out[336] = _c106;
    out[337] = _c142;
    out[338] = _c162;
    out[339] = _c202;
    out[340] = _c228;
    out[341] = _c238;
    out[342] = _c261;
    out[343] = _c271;
    out[344] = _c289;
    out[345] = _c290;
    out[346] = _c307;
    out[347] = _c292;
    out[348] = _c254;
    out[349] = _c272;
    out[350] = _c284;
    out[351] = _c322;
    out[352] = _c286;
    out[353] = _c288;
    out[354] = _c323;
    out[355] = _c132;
    out[356] = _c163;
    out[357] = _c190;
    out[358] = _c324;
    out[359] = _c239;
    out[360] = _c93;
    out[361] = _c143;
    out[362] = _c173;
    out[363] = _c191;
    out[364] = _c229;
    out[365] = _c246;
    out[366] = _c262;
    out[367] = _c278;
    out[368] = _c290;
    out[369] = _c300;
    out[370] = _c296;
    out[371] = _c301;
    out[372] = _c255;
    out[373] = _c273;
    out[374] = _c322;
    out[375] = _c295;
    out[376] = _c297;
    out[377] = _c298;
    out[378] = _c94;
    out[379] = _c325;
    out[380] = _c164;
    out[381] = _c192;
    out[382] = _c220;
    out[383] = _c326;
    out[384] = _c108;
    out[385] = _c134;
    out[386] = _c174;
    out[387] = _c204;
    out[388] = _c221;
    out[389] = _c247;
    out[390] = _c264;
    out[391] = _c279;
    out[392] = _c291;
    out[393] = _c296;
    out[394] = _c308;
    out[395] = _c305;
    out[396] = _c316;
    out[397] = _c274;
    out[398] = _c286;
    out[399] = _c297;
    out[400] = _c304;
    out[401] = _c306;
    out[402] = _c98;
    out[403] = _c135;
    out[404] = _c327;
    out[405] = _c328;
    out[406] = _c222;
    out[407] = _c241;
    out[408] = _c110;
    out[409] = _c146;
    out[410] = _c167;
    out[411] = _c206;
    out[412] = _c231;
    out[413] = _c242;
    out[414] = _c266;
    out[415] = _c281;
    out[416] = _c292;
    out[417] = _c301;
    out[418] = _c305;
    out[419] = _c313;
    out[420] = _c259;
    out[421] = _c319;
    out[422] = _c288;
    out[423] = _c298;
    out[424] = _c306;
    out[425] = _c311;
    out[426] = _c329;
    out[427] = _c138;
    out[428] = _c168;
    out[429] = _c198;
    out[430] = _c330;
    out[431] = _c243;
    out[432] = _c111;
    out[433] = _c51;
    out[434] = _c112;
    out[435] = _c113;
    out[436] = _c115;
    out[437] = _c248;
    out[438] = _c80;
    out[439] = _c282;
    out[440] = _c106;
    out[441] = _c93;
    out[442] = _c309;
    out[443] = _c110;
    out[444] = _c81;
    out[445] = _c86;
    out[446] = _c323;
    out[447] = _c94;
    out[448] = _c98;
    out[449] = _c329;
    out[450] = _c32;
    out[451] = _c52;
    out[452] = _c60;
    out[453] = _c63;
    out[454] = _c331;
    out[455] = _c77;
    out[456] = _c51;
    out[457] = _c147;
    out[458] = _c120;
    out[459] = _c208;
    out[460] = _c149;
    out[461] = _c151;
    out[462] = _c139;
    out[463] = _c128;
    out[464] = _c293;
    out[465] = _c143;
    out[466] = _c134;
    out[467] = _c314;
    out[468] = _c317;
    out[469] = _c129;
    out[470] = _c132;
    out[471] = _c325;
    out[472] = _c135;
    out[473] = _c138;
    out[474] = _c52;
    out[475] = _c118;
    out[476] = _c121;
    out[477] = _c122;
    out[478] = _c123;
    out[479] = _c332;
    out[480] = _c112;
    out[481] = _c120;
    out[482] = _c175;
    out[483] = _c176;
    out[484] = _c232;
    out[485] = _c179;
    out[486] = _c267;
    out[487] = _c171;
    out[488] = _c162;
    out[489] = _c302;
    out[490] = _c174;
    out[491] = _c167;
    out[492] = _c159;
    out[493] = _c320;
    out[494] = _c163;
    out[495] = _c164;
    out[496] = _c327;
    out[497] = _c168;
    out[498] = _c60;
    out[499] = _c121;
    out[500] = _c152;
    out[501] = _c333;
    out[502] = _c156;
    out[503] = _c158;
    out[504] = _c113;
    out[505] = _c148;
    out[506] = _c176;
    out[507] = _c209;
    out[508] = _c182;
    out[509] = _c210;
    out[510] = _c185;
    out[511] = _c200;
    out[512] = _c294;
    out[513] = _c191;
    out[514] = _c204;
    out[515] = _c315;
    out[516] = _c186;
    out[517] = _c321;
    out[518] = _c190;
    out[519] = _c192;
    out[520] = _c328;
    out[521] = _c198;
    out[522] = _c63;
    out[523] = _c122;
    out[524] = _c333;
    out[525] = _c180;
    out[526] = _c183;
    out[527] = _c184;
    out[528] = _c115;
    out[529] = _c149;
    out[530] = _c178;
    out[531] = _c182;
    out[532] = _c233;
    out[533] = _c213;
    out[534] = _c268;
    out[535] = _c216;
    out[536] = _c228;
    out[537] = _c303;
    out[538] = _c221;
    out[539] = _c231;
    out[540] = _c215;
    out[541] = _c217;
    out[542] = _c324;
    out[543] = _c220;
    out[544] = _c222;
    out[545] = _c330;
    out[546] = _c331;
    out[547] = _c123;
    out[548] = _c156;
    out[549] = _c183;
    out[550] = _c211;
    out[551] = _c214;
    out[552] = _c117;
    out[553] = _c151;
    out[554] = _c179;
    out[555] = _c210;
    out[556] = _c213;
    out[557] = _c249;
    out[558] = _c244;
    out[559] = _c283;
    out[560] = _c238;
    out[561] = _c246;
    out[562] = _c310;
    out[563] = _c242;
    out[564] = _c318;
    out[565] = _c236;
    out[566] = _c239;
    out[567] = _c326;
    out[568] = _c241;
    out[569] = _c243;
    out[570] = _c77;
    out[571] = _c332;
    out[572] = _c158;
    out[573] = _c184;
    out[574] = _c214;
    out[575] = _c234;
}

/* tet_signed_volume: Signed tetrahedron volume [m^3].
 * Returns V. */
MSSLIB_API double msslib_tet_signed_volume(double x0, double y0, double z0, double x1, double y1, double z1, double x2, double y2, double z2, double x3, double y3, double z3)
{
    return (1.0/6.0)*(-x0*y1*z2 + x0*y1*z3 + x0*y2*z1 - x0*y2*z3 - x0*y3*z1 + x0*y3*z2 + x1*y0*z2 - x1*y0*z3 - x1*y2*z0 + x1*y2*z3 + x1*y3*z0 - x1*y3*z2 - x2*y0*z1 + x2*y0*z3 + x2*y1*z0 - x2*y1*z3 - x2*y3*z0 + x2*y3*z1 + x3*y0*z1 - x3*y0*z2 - x3*y1*z0 + x3*y1*z2 + x3*y2*z0 - x3*y2*z1);
}

/* hex_averaged_volume: Golec's averaged-edge-vector volume of a hexahedron in VTK order [m^3].
 * Returns V. */
MSSLIB_API double msslib_hex_averaged_volume(double x0, double y0, double z0, double x1, double y1, double z1, double x2, double y2, double z2, double x3, double y3, double z3, double x4, double y4, double z4, double x5, double y5, double z5, double x6, double y6, double z6, double x7, double y7, double z7)
{
    const double _c0 = -z6;
    const double _c1 = _c0 + z0 + z3 - z5;
    const double _c2 = -z2 + z4;
    const double _c3 = -x6;
    const double _c4 = _c3 + x0 + x1 - x7;
    const double _c5 = -x2 + x4;
    const double _c6 = _c4 + _c5 - x3 + x5;
    const double _c7 = -y6;
    const double _c8 = _c7 + y0 + y1 - y7;
    const double _c9 = y3 - y5;
    const double _c10 = _c8 + _c9 + y2 - y4;
    const double _c11 = x3 - x5;
    const double _c12 = _c11 + _c4 + x2 - x4;
    const double _c13 = -y2 + y4;
    const double _c14 = _c13 + _c8 - y3 + y5;
    const double _c15 = z1 - z7;
    const double _c16 = _c1 + _c15 + z2 - z4;
    const double _c17 = _c0 + _c15 + _c2 + z0 - z3 + z5;
    return (1.0/64.0)*(_c10*_c17 - _c14*_c16)*(_c11 + _c3 + _c5 + x0 - x1 + x7) + (1.0/64.0)*(-_c10*_c6 + _c12*_c14)*(_c1 + _c2 - z1 + z7) + (1.0/64.0)*(-_c12*_c17 + _c16*_c6)*(_c13 + _c7 + _c9 + y0 - y1 + y7);
}

#ifdef __cplusplus
}
#endif

#endif /* MSSLIB_MSS_H */
