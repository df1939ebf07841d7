/* Test shim standing in for LinuxCNC 2.9's rtapi_math.h (uspace: the C library's math). Not LinuxCNC code. */
#ifndef CK_SHIM_RTAPI_MATH_H
#define CK_SHIM_RTAPI_MATH_H
#include <math.h>
#endif
