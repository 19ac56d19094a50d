/* SPDX-License-Identifier: Apache-2.0 */
/* The field packer of random sequential addition (src/core/rsa_field.c):
 * vp_pack_rsa hands a job with a radius or density field to it, after its
 * own checks of the parameters. */
#ifndef VDBPACK_CORE_RSA_FIELD_H
#define VDBPACK_CORE_RSA_FIELD_H

#include "vdbpack/vdbpack.h"

vp_result vp_rsa_fields_pack(vp_context *ctx, const vp_container *c, const vp_rsa_params *params,
                             vp_particles **out, vp_rsa_report *report);
#endif
