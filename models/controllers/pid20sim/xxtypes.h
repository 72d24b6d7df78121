/**********************************************************
 * This file is part of hiltwin's hand-written 20-sim test model (plants/msd20sim).
 * It has the shape of 20-sim 4.x "C++ class for 20-sim submodel" output, so that a
 * real generated folder drops into plants/<name>/ the same way. It is not generated.
 *
 * file:    xxtypes.h
 * subm:    LoopController
 **********************************************************/

/* the 20-sim data types */
#ifndef XX_TYPES_H
#define XX_TYPES_H

typedef double XXDouble;
typedef int XXInteger;
typedef short XXBoolean;
typedef char XXCharacter;
typedef XXCharacter* XXString;

#ifndef XXTRUE
#define XXTRUE 1
#endif
#ifndef XXFALSE
#define XXFALSE 0
#endif

#endif
