/*
 * models.h — internal declarations of the built-in model objects (one per source file) and
 * small shared kernels. The registry (model_registry.c) lists them in one table.
 */
#ifndef WETDEM_MODELS_H
#define WETDEM_MODELS_H

#include "wetdem.h"

/* contact */
extern const struct wetdem_model wetdem_force_hertz;
extern const struct wetdem_model wetdem_force_mindlin;
extern const struct wetdem_model wetdem_force_hooke;
extern const struct wetdem_model wetdem_hard_model;
/* fluid */
extern const struct wetdem_model wetdem_force_nijssen;
extern const struct wetdem_model wetdem_force_reynolds;
extern const struct wetdem_model wetdem_force_sb;
extern const struct wetdem_model wetdem_force_db;
extern const struct wetdem_model wetdem_force_davis;
extern const struct wetdem_model wetdem_force_nase;
extern const struct wetdem_model wetdem_force_capillary;
/* minimum separation */
extern const struct wetdem_model wetdem_minsep_fixed;
extern const struct wetdem_model wetdem_minsep_roughness;
extern const struct wetdem_model wetdem_minsep_ehd;
extern const struct wetdem_model wetdem_minsep_max;
extern const struct wetdem_model wetdem_minsep_glass;

#endif
