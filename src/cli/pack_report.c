/* SPDX-License-Identifier: Apache-2.0 */
/* `vdbpack pack`'s report: the summary, --json, and the texts the metadata
 * records (passes, counts asked and placed). */
#include "vdbpack/vdbpack.h"

#include <float.h>
#include <getopt.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "cli/cli.h"
#include "cli/pack_internal.h"

static const char *kind_name(vp_container_kind k) {
    return k == VP_CONTAINER_MESH ? "mesh" : k == VP_CONTAINER_LEVEL_SET ? "level_set" : "analytic";
}

const char *pack_lattice_label(const pack_opts *o) {
    return vp_lattice_name(o->lattice == VP_LATTICE_DEFAULT
                               ? (o->shape == VP_SHAPE_SPHERE ? VP_LATTICE_FCC : VP_LATTICE_DENSEST)
                               : o->lattice);
}

static const char *stop_name(vp_rsa_stop s) {
    return s == VP_RSA_STOP_COUNT ? "count" : s == VP_RSA_STOP_RETRIES ? "retries" : "maximal";
}

/* The passes that placed fewer than they asked for (a maximal pass never
 * does): how many, and the totals asked and placed over them. */
int pack_shortfall(const pack_opts *o, const vp_rsa_report *r, size_t *asked, size_t *placed) {
    int n = 0;
    *asked = *placed = 0;
    if (strcmp(o->method, "rsa") != 0) return 0;
    for (size_t i = 0; i < r->npasses; i++) {
        if (o->passes[i].maximal || r->passes[i].placed >= r->passes[i].requested) continue;
        n++;
        *asked += r->passes[i].requested;
        *placed += r->passes[i].placed;
    }
    return n;
}

/* The fields in the summary: one line each. */
static void summary_fields(const pack_opts *o) {
    const pack_fields *f = &o->fields;
    if (f->mask.text) printf("  mask: %s (no particle inside it)\n", f->mask.text);
    if (f->radius.text)
        printf("  radius field: %s (%s), %.6g to %.6g over the container\n", f->radius.text,
               vp_field_mode_name(f->mode), f->rmin, f->rmax);
    if (f->density.text) printf("  density field: %s\n", f->density.text);
}

/* The fields in --json (rsa). */
static void json_fields(const pack_opts *o) {
    const pack_fields *f = &o->fields;
    if (f->radius.text) {
        printf(",\"radius_field\":");
        vp_cli_json_string(stdout, f->radius.text);
        printf(",\"radius_field_mode\":\"%s\",\"radius_field_min\":%.17g,"
               "\"radius_field_max\":%.17g",
               vp_field_mode_name(f->mode), f->rmin, f->rmax);
    }
    if (f->density.text) {
        printf(",\"density_field\":");
        vp_cli_json_string(stdout, f->density.text);
    }
}

/* Per pass, what was asked (which = 0: the count, or "max") or placed
 * (1), comma-separated in pass order, for metadata ("20000,max"). */
void pack_counts_text(const pack_opts *o, const vp_rsa_report *r, int which, char *out,
                      size_t outlen) {
    size_t at = 0;
    out[0] = 0;
    for (size_t i = 0; i < r->npasses && at < outlen; i++) {
        int n = !which && o->passes[i].maximal
                    ? snprintf(out + at, outlen - at, "%smax", i ? "," : "")
                    : snprintf(out + at, outlen - at, "%s%zu", i ? "," : "",
                               which ? r->passes[i].placed : r->passes[i].requested);
        if (n < 0) break;
        at += (size_t)n;
    }
}

/* The --pass options as text, for metadata ("count=N,radius=R;..."). */
void pack_passes_text(const pack_opts *o, char *out, size_t outlen) {
    size_t at = 0;
    out[0] = 0;
    for (int i = 0; i < o->npasses && at + 1 < outlen; i++) {
        const vp_rsa_pass *ps = &o->passes[i];
        char sz[256], cnt[32];
        vp_size_dist_format(&ps->radius, sz, sizeof sz);
        if (ps->maximal) snprintf(cnt, sizeof cnt, "max");
        else snprintf(cnt, sizeof cnt, "%zu", ps->count);
        char sh[300] = "";
        if (ps->own_shape && ps->shape.shape == VP_SHAPE_MESH)
            snprintf(sh, sizeof sh, ",shape=%.280s", o->pass_mesh_file[i]);
        else if (ps->own_shape)
            vp_shape_format(ps->shape.shape, ps->shape.param,
                            sh + snprintf(sh, sizeof sh, ",shape="), sizeof sh - 7);
        int n = snprintf(out + at, outlen - at, "%scount=%s,radius=%s,retries=%d%s%s%s%s",
                         i ? ";" : "", cnt, sz, ps->retries ? ps->retries : VP_RSA_DEFAULT_RETRIES,
                         ps->grow ? ",grow" : "", ps->name[0] ? ",name=" : "", ps->name, sh);
        if (n < 0) break;
        at += (size_t)n;
        if (at >= outlen) break;
    }
}

/* A mixed set's particles per shape (counts[shape_index]); its shapes'
 * names in names (split from vp_particles_shape_list). */
static void shape_counts(const vp_particles *p, size_t *counts, char names[][300]) {
    char list[4096];
    vp_particles_shape_list(p, list, sizeof list);
    unsigned k = 0;
    for (char *a = list, *b; k < p->shape_count && k < VP_MAX_SHAPES; a = b + 1) {
        b = strchr(a, ';');
        if (b) *b = 0;
        snprintf(names[k++], 300, "%.299s", a);
        if (!b) break;
    }
    for (; k < VP_MAX_SHAPES; k++) names[k][0] = 0;
    memset(counts, 0, VP_MAX_SHAPES * sizeof *counts);
    for (size_t i = 0; i < p->count; i++) counts[p->shape_index[i]]++;
}

void pack_print_json(const pack_opts *o, const vp_container_info *ci, const vp_particles *p,
                     const run_result *rr, const vp_write_report *w, double fraction, int threads,
                     double seconds) {
    printf("{\"command\":\"pack\",\"container\":");
    vp_cli_json_string(stdout, o->container);
    printf(",\"container_kind\":\"%s\",\"container_volume\":%.17g", kind_name(ci->kind),
           ci->volume);
    if (o->fields.mask.text) {
        printf(",\"mask\":");
        vp_cli_json_string(stdout, o->fields.mask.text);
    }
    printf(",\"voxel_size\":%.17g,\"voxel_reason\":", ci->voxel_size);
    vp_cli_json_string(stdout, ci->voxel_reason);
    printf(",\"grid\":");
    vp_cli_json_string(stdout, ci->grid_name);
    printf(",\"mesh_triangles\":%zu,\"boundary_edges\":%zu,\"nonmanifold_edges\":%zu",
           ci->mesh_triangles, ci->boundary_edges, ci->nonmanifold_edges);
    if (ci->kind == VP_CONTAINER_MESH) {
        printf(",\"inconsistent_edges\":%zu,\"pieces\":%zu,\"inside\":\"%s\"",
               ci->inconsistent_edges, ci->mesh_pieces,
               ci->inside == VP_INSIDE_WINDING ? "winding" : "closed");
        printf(",\"duplicate_triangles\":%zu,\"opposite_triangles\":%zu,"
               "\"reoriented_triangles\":%zu,\"turned_pieces\":%zu,\"cavities\":%zu",
               ci->duplicate_triangles, ci->opposite_triangles, ci->reoriented_triangles,
               ci->turned_pieces, ci->cavities);
        printf(",\"volume_estimate\":%.17g,\"volume_estimate_kind\":\"%s\","
               "\"volume_mismatch\":%s",
               ci->volume_estimate,
               ci->volume_estimate_kind == VP_ESTIMATE_MESH_VOLUME ? "mesh_volume" : "winding",
               ci->volume_mismatch ? "true" : "false");
    }
    if (o->has_iso) printf(",\"iso\":%.17g", o->iso);
    printf(",\"method\":\"%s\",\"shape\":\"%s\",\"fit\":\"%s\"", o->method, o->shape_text,
           o->fit == VP_FIT_INSIDE ? "inside" : "center");
    if (o->mesh) {
        printf(",\"shape_file\":");
        vp_cli_json_string(stdout, vp_mesh_shape_name(o->mesh));
        printf(",\"shape_triangles\":%zu", vp_mesh_shape_triangles(o->mesh));
    }
    if (o->mixed) { /* the "shape" attribute's values, in order */
        size_t counts[VP_MAX_SHAPES];
        char names[VP_MAX_SHAPES][300];
        shape_counts(p, counts, names);
        printf(",\"shapes\":[");
        for (unsigned k = 0; k < p->shape_count; k++) {
            printf("%s{\"shape\":", k ? "," : "");
            vp_cli_json_string(stdout, names[k]);
            printf(",\"count\":%zu}", counts[k]);
        }
        printf("]");
    }
    printf(",\"count\":%zu,\"requested_count\":%llu,\"packing_fraction\":%.17g", p->count,
           (unsigned long long)o->count, fraction);
    {
        size_t asked, placed;
        printf(",\"short\":%s", pack_shortfall(o, &rr->rsa, &asked, &placed) ? "true" : "false");
    }
    printf(",\"max_radius\":%.17g", rr->max_radius);
    if (!strcmp(o->method, "lattice")) {
        const vp_lattice_report *l = &rr->lat;
        printf(",\"lattice\":\"%s\",\"radius\":%.17g,\"lattice_fraction\":%.17g",
               pack_lattice_label(o), l->radius, l->lattice_fraction);
        printf(",\"offsets_tried\":%d,\"rotations_tried\":%d,\"radius_iterations\":%d",
               l->offsets_tried, l->rotations_tried, l->radius_iterations);
        printf(",\"offset\":[%.17g,%.17g,%.17g],\"rotation\":[%.17g,%.17g,%.17g,%.17g]",
               l->offset[0], l->offset[1], l->offset[2], l->rotation[0], l->rotation[1],
               l->rotation[2], l->rotation[3]);
    } else if (!strcmp(o->method, "rsa")) {
        if (o->shape != VP_SHAPE_SPHERE)
            printf(",\"orient\":\"%s\",\"overlap\":\"%s\"",
                   o->orient == VP_ORIENT_FIXED ? "fixed" : "random",
                   o->overlap == VP_OVERLAP_BBOX ? "bbox" : "exact");
        if (o->rsa_count_radius) printf(",\"target_fraction\":%.17g", o->target_fraction);
        json_fields(o);
        printf(",\"passes\":[");
        for (size_t i = 0; i < rr->rsa.npasses; i++) {
            const vp_rsa_pass_report *pr = &rr->rsa.passes[i];
            char sz[256];
            vp_size_dist_format(&o->passes[i].radius, sz, sizeof sz);
            char psh[300];
            if (o->passes[i].own_shape && o->passes[i].shape.shape == VP_SHAPE_MESH)
                snprintf(psh, sizeof psh, "mesh:%.280s",
                         vp_mesh_shape_name(o->passes[i].shape.mesh));
            else if (o->passes[i].own_shape)
                vp_shape_format(o->passes[i].shape.shape, o->passes[i].shape.param, psh,
                                sizeof psh);
            else snprintf(psh, sizeof psh, "%s", o->default_shape_text);
            printf("%s{\"shape\":", i ? "," : "");
            vp_cli_json_string(stdout, psh);
            printf(",\"group\":\"%s\",\"radius\":\"%s\",\"requested\":%zu,\"maximal\":%s,"
                   "\"placed\":%zu,\"stop\":\"%s\",\"tries\":%llu,\"cell_budget_reached\":%s,"
                   "\"short\":%s,\"grow\":%s,\"grow_mean\":%.17g,\"seconds\":%.6f}",
                   p->group_names[i], sz, pr->requested, o->passes[i].maximal ? "true" : "false",
                   pr->placed, stop_name(pr->stop), (unsigned long long)pr->tries,
                   pr->budget_hit ? "true" : "false",
                   !o->passes[i].maximal && pr->placed < pr->requested ? "true" : "false",
                   o->passes[i].grow ? "true" : "false", pr->grow_mean, pr->seconds);
        }
        printf("]");
    } else if (!strcmp(o->method, "jam")) {
        const vp_jam_report *x = &rr->jam;
        printf(",\"radius_scale\":%.17g,\"max_overlap\":%.17g,\"mean_contacts\":%.17g,"
               "\"rattler_fraction\":%.17g,\"core_fraction\":%.17g,\"core_count\":%zu,"
               "\"core_volume\":%.17g,\"minimizations\":%d,\"iterations\":%ld",
               x->radius_scale, x->max_overlap, x->mean_contacts, x->rattler_fraction,
               x->core_fraction, x->core_count, x->core_volume, x->minimizations, x->iterations);
    } else {
        const vp_relax_report *x = &rr->relax;
        printf(",\"sweeps\":%d,\"radius_scale\":%.17g,\"initial_fraction\":%.17g,"
               "\"max_overlap\":%.17g",
               x->sweeps, x->radius_scale, x->initial_fraction, x->max_overlap);
    }
    if (strcmp(o->method, "rsa") != 0) json_fields(o); /* (rsa: with its passes) */
    if (strcmp(o->method, "lattice") != 0)
        printf(",\"margin\":%.17g,\"gap\":%.17g", o->margin, o->gap);
    printf(",\"seed\":%llu,\"threads\":%d,\"pack_seconds\":%.6f,\"seconds\":%.6f,\"output\":",
           (unsigned long long)o->seed, threads, rr->pack_seconds, seconds);
    vp_cli_json_string(stdout, o->output);
    if (o->out_format == VP_FORMAT_VDB)
        printf(",\"position_precision\":\"%s\",\"precision_promoted\":%s,"
               "\"position_error\":%.17g",
               w->full_precision ? "full" : "fixed16", w->promoted ? "true" : "false",
               w->position_error);
    printf("}\n");
}

void pack_print_summary(const pack_opts *o, const vp_container_info *ci, const vp_particles *p,
                        const run_result *rr, const vp_write_report *w, double fraction,
                        double seconds) {
    char what[96];
    vp_cli_shape_count(what, sizeof what, p->count, o->shape);
    if (!strcmp(o->method, "lattice"))
        printf("vdbpack: packed %s (radius %.6g) on %s in %s\n", what, rr->lat.radius,
               pack_lattice_label(o), o->container);
    else
        printf("vdbpack: packed %s%s%s%s%s by %s in %s\n", what, o->mesh ? " (" : "",
               o->mesh ? vp_mesh_shape_name(o->mesh) : "", o->mesh ? ")" : "",
               o->shape == VP_SHAPE_SPHERE     ? ""
               : o->overlap == VP_OVERLAP_BBOX ? " (fixed orientation, bounding-box overlap)"
               : o->orient == VP_ORIENT_FIXED  ? " (fixed orientation, exact overlap)"
                                               : " (random orientations, exact overlap)",
               !strcmp(o->method, "rsa")   ? "random sequential addition"
               : !strcmp(o->method, "jam") ? "jamming (random close packing)"
                                           : "relaxation",
               o->container);
    if (o->mixed) {
        size_t counts[VP_MAX_SHAPES];
        char names[VP_MAX_SHAPES][300];
        shape_counts(p, counts, names);
        printf("  shapes:");
        for (unsigned k = 0; k < p->shape_count; k++) {
            vp_shape_ref r = p->shapes[k];
            char what_k[96];
            vp_cli_shape_count(what_k, sizeof what_k, counts[k], r.shape);
            printf("%s %s", k ? "," : "", what_k);
            if (r.shape == VP_SHAPE_MESH || r.shape == VP_SHAPE_SUPERBALL)
                printf(" (%s)", r.shape == VP_SHAPE_MESH ? vp_mesh_shape_name(r.mesh) : names[k]);
            printf(" [shape %u]", k);
        }
        printf("\n");
    }
    if (ci->kind == VP_CONTAINER_MESH) vp_cli_print_mesh_container(stdout, ci);
    else if (ci->kind == VP_CONTAINER_LEVEL_SET)
        printf("  container: level set '%s', %zu active voxels, volume %.6g\n", ci->grid_name,
               ci->active_voxels, ci->volume);
    else printf("  container: analytic, volume %.6g\n", ci->volume);
    if (ci->voxel_size > 0) printf("  voxel size %.6g: %s\n", ci->voxel_size, ci->voxel_reason);
    summary_fields(o);
    if (o->margin > 0 || o->gap > 0)
        printf("  kept apart: margin %g from the wall, gap %g between surfaces\n", o->margin,
               o->gap);
    if (!strcmp(o->method, "lattice")) {
        const vp_lattice_report *l = &rr->lat;
        printf("  placement: %d offsets tried over %d orientation%s", l->offsets_tried,
               l->rotations_tried, l->rotations_tried == 1 ? "" : "s");
        if (o->count) {
            printf(", %d %s tried for --count %llu", l->radius_iterations,
                   l->radius_iterations == 1 ? "radius" : "radii", (unsigned long long)o->count);
            double off = fabs((double)l->count - (double)o->count);
            if (off > 0.02 * (double)o->count)
                printf(" (%zu is the closest count found: with few particles, or layers "
                       "in a box, the count jumps as the radius changes)",
                       l->count);
        }
        printf("\n  packing fraction %.4f (the infinite lattice: %.4f)\n", fraction,
               l->lattice_fraction);
    } else if (!strcmp(o->method, "rsa")) {
        if (o->rsa_count_radius)
            printf("  radius %.6g: %llu of them fill %.3g of the container (--target-fraction)\n",
                   vp_size_dist_max(&o->passes[0].radius), (unsigned long long)o->count,
                   o->target_fraction);
        for (size_t i = 0; i < rr->rsa.npasses; i++) {
            const vp_rsa_pass_report *pr = &rr->rsa.passes[i];
            char sz[256];
            vp_size_dist_format(&o->passes[i].radius, sz, sizeof sz);
            printf("  %s: radius %s, placed %zu", p->group_names[i], sz, pr->placed);
            if (o->passes[i].maximal && pr->stop == VP_RSA_STOP_MAXIMAL)
                printf(" (maximal: no room left)");
            else if (o->passes[i].maximal && (o->fields.radius_field || o->fields.density_field))
                printf(" (with a field, count=max ends after %d failed tries in a row, see "
                       "docs/fields.md)",
                       o->passes[i].retries ? o->passes[i].retries : VP_RSA_DEFAULT_RETRIES);
            else if (o->passes[i].maximal && o->shape != VP_SHAPE_SPHERE)
                printf(" (maximal mode for %s: stopped by %d failed tries in a row, see "
                       "docs/rsa.md)",
                       o->mixed ? "several shapes" : "solids",
                       o->passes[i].retries ? o->passes[i].retries : VP_RSA_DEFAULT_RETRIES);
            else if (o->passes[i].maximal)
                printf(" (maximal mode stopped by %d failed tries in a row: refining the empty "
                       "space further would exceed its memory budget)",
                       o->passes[i].retries ? o->passes[i].retries : VP_RSA_DEFAULT_RETRIES);
            else if (pr->stop == VP_RSA_STOP_RETRIES)
                printf(" of %zu (stopped: %d failed tries in a row)", pr->requested,
                       o->passes[i].retries ? o->passes[i].retries : VP_RSA_DEFAULT_RETRIES);
            else if (pr->stop == VP_RSA_STOP_MAXIMAL && pr->placed < pr->requested)
                printf(" of %zu (stopped: no room left for another)", pr->requested);
            else printf(" of %zu", pr->requested);
            if (o->passes[i].grow) printf(", grown by %.3fx on average", pr->grow_mean);
            printf(", %.2f s\n", pr->seconds);
        }
        printf("  packing fraction %.4f%s\n", fraction,
               fraction > 1.0 ? " (over 1: with --fit center the wall does not hold the "
                                "particles, nor their growth)"
                              : "");
    } else if (!strcmp(o->method, "jam")) {
        const vp_jam_report *x = &rr->jam;
        printf("  jamming: %d minimisations, %ld FIRE steps; radii scaled by %.6g; largest "
               "overlap %.3g of r_i + r_j\n",
               x->minimizations, x->iterations, x->radius_scale, x->max_overlap);
        /* a jammed packing has a few rattlers (5 to 15 % in a box); a
         * third or more: the contact network does not hold the packing
         * (a long channel a few diameters across can end so: its
         * pressure not yet even along it, docs/jam.md) */
        printf("  contacts: Z = %.3f over non-rattlers, rattlers %.1f %%%s\n", x->mean_contacts,
               100.0 * x->rattler_fraction,
               x->rattler_fraction >= 1.0 / 3.0
                   ? " (a third or more: not jammed; long narrow containers can end so: "
                     "docs/jam.md)"
                   : "");
        if (x->core_count)
            printf("  packing fraction %.4f (core, 5 diameters from the wall: %.4f over %zu "
                   "spheres)\n",
                   fraction, x->core_fraction, x->core_count);
        else printf("  packing fraction %.4f (no core 5 diameters from the wall)\n", fraction);
    } else {
        const vp_relax_report *x = &rr->relax;
        printf("  relaxation: %d sweeps, radii scaled by %.4f, largest overlap %.3g of r_i + r_j\n",
               x->sweeps, x->radius_scale, x->max_overlap);
        printf("  packing fraction %.4f (%.4f before relaxation)\n", fraction, x->initial_fraction);
    }
    if (o->out_format == VP_FORMAT_VDB && w->promoted) vp_cli_print_promoted(w);
    printf("  wrote %s in %.2f s (packing %.2f s)\n", o->output, seconds, rr->pack_seconds);
}
