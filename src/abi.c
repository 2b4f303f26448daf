/*
 * abi.c — sizes of the public value types, so that bindings mirroring them (ctypes) can check
 * their layout at import time.
 */
#include <string.h>

#include "wetdem.h"

size_t wetdem_abi_sizeof(const char* type_name)
{
    static const struct {
        const char* name;
        size_t size;
    } sizes[] = {
        {"vec3", sizeof(struct wetdem_vec3)},
        {"particle", sizeof(struct wetdem_particle)},
        {"material", sizeof(struct wetdem_material)},
        {"fluid", sizeof(struct wetdem_fluid)},
        {"contact", sizeof(struct wetdem_contact)},
        {"pair_force", sizeof(struct wetdem_pair_force)},
    };
    for (size_t k = 0; type_name && k < sizeof sizes / sizeof sizes[0]; k++)
        if (strcmp(sizes[k].name, type_name) == 0)
            return sizes[k].size;
    return 0;
}
