/**********************************************************
 * This file is part of hiltwin's hand-written 20-sim test model (plants/msd20sim),
 * in the shape of 20-sim 4.x C++ class output. It is not generated.
 *
 * file:    xxmatrix.h
 * subm:    LoopController
 **********************************************************/

/* the 20-sim matrix type: this model has no matrices, so only the type is here */
#ifndef XX_MATRIX_H
#define XX_MATRIX_H

#include "xxtypes.h"

struct XXMatrix
{
	XXDouble *mat;
	XXInteger rows;
	XXInteger columns;
};

#endif
