/* Test shim standing in for what a halcompile'd kinematics component sees of LinuxCNC 2.9: the declarations of
 * hal.h, rtapi.h and src/emc/kinematics/kinematics.h it uses, and the comp_id that halcompile's prologue defines.
 * Written for cnccomp's tests from those headers' documented interfaces; not LinuxCNC code. */
#ifndef CK_SHIM_KINEMATICS_H
#define CK_SHIM_KINEMATICS_H
#include <stdbool.h>
#include <stdint.h>

typedef volatile double hal_float_t;
typedef volatile bool hal_bit_t;
typedef volatile int32_t hal_s32_t;
typedef enum { HAL_IN = 16, HAL_OUT = 32, HAL_IO = 48 } hal_pin_dir_t;

int hal_pin_float_newf(hal_pin_dir_t dir, hal_float_t **data_ptr_addr, int comp_id, const char *fmt, ...);
int hal_pin_bit_newf(hal_pin_dir_t dir, hal_bit_t **data_ptr_addr, int comp_id, const char *fmt, ...);
int hal_pin_s32_newf(hal_pin_dir_t dir, hal_s32_t **data_ptr_addr, int comp_id, const char *fmt, ...);
void *hal_malloc(long int size);
int hal_set_unready(int comp_id);
int hal_ready(int comp_id);

#define RTAPI_MSG_ERR 1
#define RTAPI_MSG_INFO 3
void rtapi_print_msg(int level, const char *fmt, ...);
#define EXPORT_SYMBOL(x)

static int comp_id __attribute__((unused)) = 1; /* halcompile: set by hal_init() in rtapi_app_main */

typedef struct { double x, y, z; } PmCartesian;
typedef struct EmcPose { PmCartesian tran; double a, b, c; double u, v, w; } EmcPose;
typedef enum {
    KINEMATICS_IDENTITY = 1,
    KINEMATICS_FORWARD_ONLY,
    KINEMATICS_INVERSE_ONLY,
    KINEMATICS_BOTH
} KINEMATICS_TYPE;
typedef unsigned long int KINEMATICS_FORWARD_FLAGS;
typedef unsigned long int KINEMATICS_INVERSE_FLAGS;

int kinematicsForward(const double *joint, EmcPose *world, const KINEMATICS_FORWARD_FLAGS *fflags,
                      KINEMATICS_INVERSE_FLAGS *iflags);
int kinematicsInverse(const EmcPose *world, double *joint, const KINEMATICS_INVERSE_FLAGS *iflags,
                      KINEMATICS_FORWARD_FLAGS *fflags);
KINEMATICS_TYPE kinematicsType(void);
int kinematicsSwitchable(void);
int kinematicsSwitch(int switchkins_type);

/* Test access to a pin's storage by its full name (NULL when none). */
void *shim_pin(const char *name);
#endif
