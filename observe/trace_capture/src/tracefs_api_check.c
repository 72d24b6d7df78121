/* Compiles tracefs_api.h against the library's own header: a declaration there that differs
 * from <tracefs.h> is a "conflicting types" error here. Declarations only; no code. */
#include <tracefs.h>

#include "tracefs_api.h"
