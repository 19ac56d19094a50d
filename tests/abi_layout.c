/* SPDX-License-Identifier: Apache-2.0 */
/* Prints, as JSON, the size and field offsets of every public struct the
 * Python module mirrors with ctypes (python/vdbpack/_lib.py), and the
 * constants it copies, as the compiler lays them out from the installed
 * headers. tests/python/test_abi.py compares them with ctypes' layout, so
 * that a header change not made in the module fails a test. */
#include <stddef.h>
#include <stdio.h>

#include "vdbpack/vdbpack.h"

static int first_struct = 1, first_field = 1;

static void begin(const char *name, size_t size) {
    printf("%s\n  \"%s\": {\"size\": %zu, \"fields\": {", first_struct ? "" : "},", name, size);
    first_struct = 0;
    first_field = 1;
}

static void field(const char *name, size_t offset, size_t size) {
    printf("%s\"%s\": [%zu, %zu]", first_field ? "" : ", ", name, offset, size);
    first_field = 0;
}

#define S(T) begin(#T, sizeof(T))
#define F(T, f) field(#f, offsetof(T, f), sizeof(((T *)0)->f))

static void structs(void) {
    S(vp_container_ops);
    F(vp_container_ops, distance);
    F(vp_container_ops, gradient);
    F(vp_container_ops, destroy);
    printf("}");

    S(vp_container_info);
    F(vp_container_info, kind);
    F(vp_container_info, bmin);
    F(vp_container_info, bmax);
    F(vp_container_info, volume);
    F(vp_container_info, voxel_size);
    F(vp_container_info, interior_band);
    F(vp_container_info, voxel_reason);
    F(vp_container_info, grid_name);
    F(vp_container_info, active_voxels);
    F(vp_container_info, mesh_vertices);
    F(vp_container_info, mesh_vertices_raw);
    F(vp_container_info, mesh_triangles);
    F(vp_container_info, boundary_edges);
    F(vp_container_info, nonmanifold_edges);
    F(vp_container_info, mesh_volume);
    F(vp_container_info, inconsistent_edges);
    F(vp_container_info, mesh_pieces);
    F(vp_container_info, inside);
    F(vp_container_info, duplicate_triangles);
    F(vp_container_info, opposite_triangles);
    F(vp_container_info, reoriented_triangles);
    F(vp_container_info, turned_pieces);
    F(vp_container_info, cavities);
    F(vp_container_info, volume_estimate_kind);
    F(vp_container_info, volume_estimate);
    F(vp_container_info, volume_mismatch);
    F(vp_container_info, iso);
    printf("}");

    S(vp_container_params);
    F(vp_container_params, voxel_size);
    F(vp_container_params, particle_radius);
    F(vp_container_params, particle_count);
    F(vp_container_params, space_per_particle);
    F(vp_container_params, inside);
    F(vp_container_params, grid_name);
    F(vp_container_params, has_iso);
    F(vp_container_params, iso);
    F(vp_container_params, narrow_band);
    F(vp_container_params, name);
    F(vp_container_params, extra_depth);
    printf("}");

    S(vp_particles);
    F(vp_particles, count);
    F(vp_particles, capacity);
    F(vp_particles, positions);
    F(vp_particles, radii);
    F(vp_particles, uniform_radius);
    F(vp_particles, orients);
    F(vp_particles, uniform_orient);
    F(vp_particles, has_orient);
    F(vp_particles, shape);
    F(vp_particles, mesh);
    F(vp_particles, groups);
    F(vp_particles, group_count);
    F(vp_particles, group_names);
    F(vp_particles, position_error);
    F(vp_particles, shape_param);
    F(vp_particles, shape_index);
    F(vp_particles, shape_count);
    F(vp_particles, shapes);
    F(vp_particles, shape_names);
    printf("}");

    S(vp_shape_ref);
    F(vp_shape_ref, shape);
    F(vp_shape_ref, param);
    F(vp_shape_ref, mesh);
    printf("}");

    S(vp_lattice_params);
    F(vp_lattice_params, shape);
    F(vp_lattice_params, lattice);
    F(vp_lattice_params, fit);
    F(vp_lattice_params, radius);
    F(vp_lattice_params, count);
    F(vp_lattice_params, offsets);
    F(vp_lattice_params, rotate);
    F(vp_lattice_params, rotations);
    F(vp_lattice_params, seed);
    F(vp_lattice_params, shape_param);
    F(vp_lattice_params, margin);
    F(vp_lattice_params, gap);
    printf("}");

    S(vp_lattice_report);
    F(vp_lattice_report, radius);
    F(vp_lattice_report, count);
    F(vp_lattice_report, offsets_tried);
    F(vp_lattice_report, rotations_tried);
    F(vp_lattice_report, radius_iterations);
    F(vp_lattice_report, offset);
    F(vp_lattice_report, rotation);
    F(vp_lattice_report, lattice_fraction);
    F(vp_lattice_report, particle_volume);
    F(vp_lattice_report, seconds);
    printf("}");

    S(vp_meta);
    F(vp_meta, key);
    F(vp_meta, type);
    F(vp_meta, s);
    F(vp_meta, i);
    F(vp_meta, d);
    printf("}");

    S(vp_write_report);
    F(vp_write_report, full_precision);
    F(vp_write_report, promoted);
    F(vp_write_report, voxel_size);
    F(vp_write_report, position_error);
    F(vp_write_report, fixed16_error);
    F(vp_write_report, min_radius);
    printf("}");

    S(vp_write_params);
    F(vp_write_params, full_precision);
    F(vp_write_params, points_per_voxel);
    F(vp_write_params, meta);
    F(vp_write_params, meta_count);
    F(vp_write_params, report);
    F(vp_write_params, max_memory);
    printf("}");

    S(vp_size_dist);
    F(vp_size_dist, kind);
    F(vp_size_dist, a);
    F(vp_size_dist, b);
    F(vp_size_dist, n);
    F(vp_size_dist, values);
    printf("}");

    S(vp_field_info);
    F(vp_field_info, bmin);
    F(vp_field_info, bmax);
    F(vp_field_info, voxel_size);
    F(vp_field_info, min);
    F(vp_field_info, max);
    F(vp_field_info, grid_name);
    printf("}");

    S(vp_rsa_pass);
    F(vp_rsa_pass, count);
    F(vp_rsa_pass, maximal);
    F(vp_rsa_pass, radius);
    F(vp_rsa_pass, retries);
    F(vp_rsa_pass, grow);
    F(vp_rsa_pass, name);
    F(vp_rsa_pass, own_shape);
    F(vp_rsa_pass, shape);
    printf("}");

    S(vp_rsa_params);
    F(vp_rsa_params, fit);
    F(vp_rsa_params, shape);
    F(vp_rsa_params, mesh);
    F(vp_rsa_params, orient);
    F(vp_rsa_params, overlap);
    F(vp_rsa_params, passes);
    F(vp_rsa_params, npasses);
    F(vp_rsa_params, seed);
    F(vp_rsa_params, max_cells);
    F(vp_rsa_params, shape_param);
    F(vp_rsa_params, margin);
    F(vp_rsa_params, gap);
    F(vp_rsa_params, radius_field);
    F(vp_rsa_params, radius_field_mode);
    F(vp_rsa_params, density_field);
    printf("}");

    S(vp_rsa_pass_report);
    F(vp_rsa_pass_report, requested);
    F(vp_rsa_pass_report, placed);
    F(vp_rsa_pass_report, stop);
    F(vp_rsa_pass_report, tries);
    F(vp_rsa_pass_report, pretested);
    F(vp_rsa_pass_report, budget_hit);
    F(vp_rsa_pass_report, grow_mean);
    F(vp_rsa_pass_report, seconds);
    printf("}");

    S(vp_rsa_report);
    F(vp_rsa_report, npasses);
    F(vp_rsa_report, passes);
    F(vp_rsa_report, particle_volume);
    F(vp_rsa_report, seconds);
    printf("}");

    S(vp_relax_params);
    F(vp_relax_params, fit);
    F(vp_relax_params, radius);
    F(vp_relax_params, count);
    F(vp_relax_params, target_fraction);
    F(vp_relax_params, tolerance);
    F(vp_relax_params, max_sweeps);
    F(vp_relax_params, seed);
    F(vp_relax_params, margin);
    F(vp_relax_params, gap);
    F(vp_relax_params, radius_field);
    F(vp_relax_params, radius_field_mode);
    printf("}");

    S(vp_relax_report);
    F(vp_relax_report, count);
    F(vp_relax_report, sweeps);
    F(vp_relax_report, radius_scale);
    F(vp_relax_report, initial_fraction);
    F(vp_relax_report, max_overlap);
    F(vp_relax_report, particle_volume);
    F(vp_relax_report, seconds);
    printf("}");

    S(vp_jam_params);
    F(vp_jam_params, fit);
    F(vp_jam_params, radius);
    F(vp_jam_params, count);
    F(vp_jam_params, target_fraction);
    F(vp_jam_params, tolerance);
    F(vp_jam_params, contact_gap);
    F(vp_jam_params, seed);
    F(vp_jam_params, margin);
    F(vp_jam_params, gap);
    F(vp_jam_params, radius_field);
    F(vp_jam_params, radius_field_mode);
    printf("}");

    S(vp_jam_report);
    F(vp_jam_report, count);
    F(vp_jam_report, fraction);
    F(vp_jam_report, core_fraction);
    F(vp_jam_report, core_count);
    F(vp_jam_report, core_volume);
    F(vp_jam_report, mean_contacts);
    F(vp_jam_report, rattler_fraction);
    F(vp_jam_report, max_overlap);
    F(vp_jam_report, radius_scale);
    F(vp_jam_report, particle_volume);
    F(vp_jam_report, minimizations);
    F(vp_jam_report, iterations);
    F(vp_jam_report, list_builds);
    F(vp_jam_report, seconds);
    printf("}");

    S(vp_check_params);
    F(vp_check_params, fit);
    F(vp_check_params, overlap_tolerance);
    F(vp_check_params, contact_tolerance);
    F(vp_check_params, wall_tolerance);
    F(vp_check_params, position_tolerance);
    F(vp_check_params, margin);
    F(vp_check_params, gap);
    printf("}");

    S(vp_check_report);
    F(vp_check_report, count);
    F(vp_check_report, overlapping_pairs);
    F(vp_check_report, max_overlap);
    F(vp_check_report, max_overlap_world);
    F(vp_check_report, outside);
    F(vp_check_report, max_outside);
    F(vp_check_report, particle_volume);
    F(vp_check_report, container_volume);
    F(vp_check_report, fraction);
    F(vp_check_report, mean_contacts);
    F(vp_check_report, contact_pairs);
    F(vp_check_report, position_error_ratio);
    F(vp_check_report, imprecise);
    F(vp_check_report, seconds);
    printf("}");

    S(vp_render_params);
    F(vp_render_params, width);
    F(vp_render_params, height);
    F(vp_render_params, view);
    F(vp_render_params, eye);
    F(vp_render_params, target);
    F(vp_render_params, up);
    F(vp_render_params, fov_degrees);
    F(vp_render_params, colour);
    F(vp_render_params, cut_axis);
    F(vp_render_params, cut_value);
    F(vp_render_params, ao_samples);
    F(vp_render_params, shadows);
    printf("}");

    S(vp_image);
    F(vp_image, width);
    F(vp_image, height);
    F(vp_image, rgba);
    F(vp_image, z);
    F(vp_image, id);
    printf("}");

    S(vp_export_params);
    F(vp_export_params, format);
    F(vp_export_params, vdb);
    F(vp_export_params, sphere_subdivisions);
    printf("}");
}

static int first_const = 1;

static void constant(const char *name, long long value) {
    printf("%s\"%s\": %lld", first_const ? "" : ", ", name, value);
    first_const = 0;
}

#define C(x) constant(#x, (long long)(x))

int main(void) {
    printf("{\"structs\": {");
    structs();
    printf("}},\n\"enum_size\": %zu,\n\"constants\": {", sizeof(vp_result));
    C(VP_MAX_GROUPS);
    C(VP_GROUP_NAME_MAX);
    C(VP_SIZE_LIST_MAX);
    C(VP_RSA_DEFAULT_RETRIES);
    C(VP_RENDER_BACKGROUND_ID);
    C(VP_OK);
    C(VP_ERR_INVALID_ARGUMENT);
    C(VP_ERR_IO);
    C(VP_ERR_FORMAT);
    C(VP_ERR_OPEN_MESH);
    C(VP_ERR_NOT_LEVEL_SET);
    C(VP_ERR_BAD_CONTAINER);
    C(VP_ERR_NO_FIT);
    C(VP_ERR_OUT_OF_MEMORY);
    C(VP_ERR_CANCELLED);
    C(VP_ERR_INTERNAL);
    C(VP_SHAPE_SPHERE);
    C(VP_SHAPE_TETRAHEDRON);
    C(VP_SHAPE_CUBE);
    C(VP_SHAPE_OCTAHEDRON);
    C(VP_SHAPE_DODECAHEDRON);
    C(VP_SHAPE_ICOSAHEDRON);
    C(VP_SHAPE_TRUNCATED_TETRAHEDRON);
    C(VP_SHAPE_CUBOCTAHEDRON);
    C(VP_SHAPE_TRUNCATED_CUBE);
    C(VP_SHAPE_TRUNCATED_OCTAHEDRON);
    C(VP_SHAPE_RHOMBICUBOCTAHEDRON);
    C(VP_SHAPE_TRUNCATED_CUBOCTAHEDRON);
    C(VP_SHAPE_SNUB_CUBE);
    C(VP_SHAPE_ICOSIDODECAHEDRON);
    C(VP_SHAPE_TRUNCATED_DODECAHEDRON);
    C(VP_SHAPE_TRUNCATED_ICOSAHEDRON);
    C(VP_SHAPE_RHOMBICOSIDODECAHEDRON);
    C(VP_SHAPE_TRUNCATED_ICOSIDODECAHEDRON);
    C(VP_SHAPE_SNUB_DODECAHEDRON);
    C(VP_SHAPE_COUNT);
    C(VP_SHAPE_MESH);
    C(VP_SHAPE_MIXED);
    C(VP_MAX_SHAPES);
    C(VP_SHAPE_NAME_MAX);
    C(VP_LATTICE_DEFAULT);
    C(VP_LATTICE_SC);
    C(VP_LATTICE_BCC);
    C(VP_LATTICE_FCC);
    C(VP_LATTICE_HCP);
    C(VP_LATTICE_DENSEST);
    C(VP_FIT_INSIDE);
    C(VP_FIT_CENTER);
    C(VP_ORIENT_RANDOM);
    C(VP_ORIENT_FIXED);
    C(VP_OVERLAP_EXACT);
    C(VP_OVERLAP_BBOX);
    C(VP_INSIDE_AUTO);
    C(VP_INSIDE_CLOSED);
    C(VP_INSIDE_WINDING);
    C(VP_CONTAINER_ANALYTIC);
    C(VP_CONTAINER_MESH);
    C(VP_CONTAINER_LEVEL_SET);
    C(VP_ESTIMATE_NONE);
    C(VP_ESTIMATE_MESH_VOLUME);
    C(VP_ESTIMATE_WINDING);
    C(VP_RSA_STOP_COUNT);
    C(VP_RSA_STOP_RETRIES);
    C(VP_RSA_STOP_MAXIMAL);
    C(VP_SIZE_CONSTANT);
    C(VP_SIZE_UNIFORM);
    C(VP_SIZE_LOGNORMAL);
    C(VP_SIZE_LIST);
    C(VP_FORMAT_UNKNOWN);
    C(VP_FORMAT_VDB);
    C(VP_FORMAT_PLY);
    C(VP_FORMAT_CSV);
    C(VP_FORMAT_OBJ);
    C(VP_VIEW_ISO);
    C(VP_VIEW_FRONT);
    C(VP_VIEW_TOP);
    C(VP_VIEW_CAMERA);
    C(VP_COLOUR_PASS);
    C(VP_COLOUR_SIZE);
    C(VP_COLOUR_ID);
    C(VP_COLOUR_CONTACTS);
    C(VP_META_STRING);
    C(VP_META_INT);
    C(VP_META_DOUBLE);
    printf("}}\n");
    return 0;
}
