/* Test shim: the HAL and RTAPI calls a kinematics component makes, backed by static storage, and shim_pin() for the
 * tests to read and set pins by name. Not LinuxCNC code. */
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

#include "kinematics.h"

#define SHIM_MAX_PINS 512
static struct { char name[64]; union { double f; bool b; int32_t s; } value; } shim_pins[SHIM_MAX_PINS];
static int shim_npins = 0;
static double shim_heap[4096];
static long shim_heap_used = 0;

static void *shim_new(const char *fmt, va_list ap) {
    if (shim_npins >= SHIM_MAX_PINS) return NULL;
    vsnprintf(shim_pins[shim_npins].name, sizeof shim_pins[shim_npins].name, fmt, ap);
    for (int i = 0; i < shim_npins; ++i)
        if (strcmp(shim_pins[i].name, shim_pins[shim_npins].name) == 0) return NULL; /* HAL refuses duplicates */
    return &shim_pins[shim_npins++].value;
}

/* hal_pin_<type>_newf: one definition per HAL pin type, all on shim_new. */
#define SHIM_PIN_NEWF(type)                                                                   \
    int hal_pin_##type##_newf(hal_pin_dir_t dir, hal_##type##_t **p, int id, const char *fmt, ...) { \
        va_list ap;                                                                           \
        void *v;                                                                              \
        (void)dir; (void)id;                                                                  \
        va_start(ap, fmt);                                                                    \
        v = shim_new(fmt, ap);                                                                \
        va_end(ap);                                                                           \
        if (!v) return -1;                                                                    \
        *p = (hal_##type##_t *)v;                                                             \
        return 0;                                                                             \
    }
SHIM_PIN_NEWF(float)
SHIM_PIN_NEWF(bit)
SHIM_PIN_NEWF(s32)

void *hal_malloc(long int size) {
    const long words = (size + (long)sizeof(double) - 1) / (long)sizeof(double);
    void *p;
    if (shim_heap_used + words > (long)(sizeof shim_heap / sizeof shim_heap[0])) return NULL;
    p = &shim_heap[shim_heap_used];
    shim_heap_used += words;
    return p;
}

int hal_set_unready(int id) { (void)id; return 0; }
int hal_ready(int id) { (void)id; return 0; }
void rtapi_print_msg(int level, const char *fmt, ...) { (void)level; (void)fmt; }

void *shim_pin(const char *name) {
    for (int i = 0; i < shim_npins; ++i)
        if (strcmp(shim_pins[i].name, name) == 0) return &shim_pins[i].value;
    return NULL;
}
