// Generated from the modules of derivations/elements/ and derivations/terms/ by
// `python -m derivations.codegen`. Do not edit; rewritten when a module is added.
/* Every C header of msslib/generated/c: spring constants, rest-length factors, volume
 * coefficients and the energy, gradient and Hessian kernels of msslib's mass-spring models.
 * Each header also stands alone. */
#ifndef MSSLIB_MSS_H
#define MSSLIB_MSS_H

#include "msslib_triangle.h"
#include "msslib_triangle_angular.h"
#include "msslib_triangle_lsq.h"
#include "msslib_square.h"
#include "msslib_rectangle.h"
#include "msslib_tetrahedron.h"
#include "msslib_kikuuwe_tetrahedron.h"
#include "msslib_tetrahedron_lsq.h"
#include "msslib_cube_baudet.h"
#include "msslib_cube_golec.h"
#include "msslib_kernels.h"

#endif /* MSSLIB_MSS_H */
