# SPDX-License-Identifier: Apache-2.0
"""Finding and loading libvdbpack, and the ctypes mirror of its C API.

The structs below mirror include/vdbpack/*.h field by field; the test
tests/python/test_abi.py compares their sizes and offsets with a C program
compiled against the headers (tests/abi_layout.c), so that a change on one
side without the other fails a test instead of corrupting memory.
"""
import ctypes
import ctypes.util
import os

# ---------------------------------------------------------------------------
# Loading

_ENV = "VDBPACK_LIBRARY"


def _load():
    """Returns (CDLL, path). Lookup order: $VDBPACK_LIBRARY (when set, the
    only one tried: an explicit choice that fails must not silently become
    another library), then the path in _libpath.py (written by the build or
    the installation), then ctypes.util.find_library("vdbpack")."""
    try:
        from . import _libpath
    except ImportError:
        _libpath = None
    env = os.environ.get(_ENV)
    if env:
        try:
            return ctypes.CDLL(env), env, _libpath
        except OSError as e:
            raise ImportError(
                "vdbpack: cannot load the library named by %s=%s (%s); set %s to the path "
                "of libvdbpack.so, or unset it to use the one this module was built or "
                "installed with" % (_ENV, env, _reason(e), _ENV)) from None
    tried = []
    if _libpath is None:
        tried.append("_libpath.py: absent from %s" % os.path.dirname(os.path.abspath(__file__)))
    else:
        path = _libpath.LIBRARY
        if _libpath.RELATIVE:
            path = os.path.normpath(os.path.join(os.path.dirname(_libpath.__file__), path))
        try:
            return ctypes.CDLL(path), path, _libpath
        except OSError as e:
            tried.append("_libpath.py: %s (%s)" % (path, _reason(e)))
    name = ctypes.util.find_library("vdbpack")
    if name:
        try:
            return ctypes.CDLL(name), name, _libpath
        except OSError as e:
            tried.append("find_library('vdbpack'): %s (%s)" % (name, _reason(e)))
    else:
        tried.append("ctypes.util.find_library('vdbpack'): not found")
    raise ImportError("vdbpack: cannot load the libvdbpack shared library; tried %s. Set %s "
                      "to the path of libvdbpack.so" % ("; ".join(tried), _ENV))


def _reason(e):
    # dlopen's message repeats the path; keep the part after the last ': '
    text = str(e)
    return text.rsplit(": ", 1)[-1] if ": " in text else text


lib, LIBRARY_PATH, _libpath = _load()

# ---------------------------------------------------------------------------
# Constants (vdbpack.h and the per-topic headers)

VP_MAX_GROUPS = 64
VP_GROUP_NAME_MAX = 32
VP_MAX_SHAPES = 16
VP_SHAPE_NAME_MAX = 64
VP_SIZE_LIST_MAX = 64
VP_RSA_DEFAULT_RETRIES = 5000
VP_RENDER_BACKGROUND_ID = 0xFFFFFFFF
VP_POSITION_ERROR_LIMIT = 1e-3

RESULT_NAMES = ("VP_OK", "VP_ERR_INVALID_ARGUMENT", "VP_ERR_IO", "VP_ERR_FORMAT",
                "VP_ERR_OPEN_MESH", "VP_ERR_NOT_LEVEL_SET", "VP_ERR_BAD_CONTAINER",
                "VP_ERR_NO_FIT", "VP_ERR_OUT_OF_MEMORY", "VP_ERR_CANCELLED", "VP_ERR_INTERNAL")
VP_OK = 0
VP_ERR_INVALID_ARGUMENT = 1
VP_ERR_CANCELLED = 9
VP_ERR_INTERNAL = 10

# vp_shape order: the platonic solids, then the 13 Archimedean ones
SHAPES = ("sphere", "tetrahedron", "cube", "octahedron", "dodecahedron", "icosahedron") + \
    ("truncated-tetrahedron", "cuboctahedron", "truncated-cube", "truncated-octahedron",
     "rhombicuboctahedron", "truncated-cuboctahedron", "snub-cube", "icosidodecahedron",
     "truncated-dodecahedron", "truncated-icosahedron", "rhombicosidodecahedron",
     "truncated-icosidodecahedron", "snub-dodecahedron")
VP_SHAPE_SPHERE = 0
VP_SHAPE_MESH = 64
VP_SHAPE_MIXED = 66
VP_SHAPE_SUPERBALL = 65  # "superball:P": the exponent P is the params' shape_param
LATTICES = {"sc": 1, "bcc": 2, "fcc": 3, "hcp": 4, "densest": 5}
VP_LATTICE_DEFAULT = 0
VP_LATTICE_FCC = 3
VP_LATTICE_DENSEST = 5
FITS = {"inside": 0, "center": 1, "centre": 1}
ORIENTS = {"random": 0, "fixed": 1}
OVERLAPS = {"exact": 0, "bbox": 1}
INSIDE_MODES = {"auto": 0, "closed": 1, "winding": 2}
KINDS = ("analytic", "mesh", "level_set")
ESTIMATES = ("none", "mesh_volume", "winding")
RSA_STOPS = ("count", "retries", "maximal")
FORMATS = {"vdb": 1, "ply": 2, "csv": 3, "obj": 4}
VIEWS = {"iso": 0, "front": 1, "top": 2, "camera": 3}
COLOURS = {"pass": 0, "size": 1, "id": 2, "contacts": 3}
VP_META_STRING, VP_META_INT, VP_META_DOUBLE = 0, 1, 2

# ---------------------------------------------------------------------------
# Structs

c_double3 = ctypes.c_double * 3
c_double4 = ctypes.c_double * 4
_e = ctypes.c_int  # every vdbpack enum has int's size and alignment (its values fit)

DISTANCE_FN = ctypes.CFUNCTYPE(ctypes.c_double, ctypes.c_void_p, ctypes.POINTER(ctypes.c_double))
GRADIENT_FN = ctypes.CFUNCTYPE(None, ctypes.c_void_p, ctypes.POINTER(ctypes.c_double),
                               ctypes.POINTER(ctypes.c_double))
DESTROY_FN = ctypes.CFUNCTYPE(None, ctypes.c_void_p)
PROGRESS_FN = ctypes.CFUNCTYPE(ctypes.c_int, ctypes.c_void_p, ctypes.c_double, ctypes.c_char_p)


class vp_container_ops(ctypes.Structure):
    _fields_ = [("distance", DISTANCE_FN), ("gradient", GRADIENT_FN), ("destroy", DESTROY_FN)]


class vp_container_info(ctypes.Structure):
    _fields_ = [
        ("kind", _e), ("bmin", c_double3), ("bmax", c_double3), ("volume", ctypes.c_double),
        ("voxel_size", ctypes.c_double), ("interior_band", ctypes.c_double),
        ("voxel_reason", ctypes.c_char * 160), ("grid_name", ctypes.c_char * 128),
        ("active_voxels", ctypes.c_size_t), ("mesh_vertices", ctypes.c_size_t),
        ("mesh_vertices_raw", ctypes.c_size_t), ("mesh_triangles", ctypes.c_size_t),
        ("boundary_edges", ctypes.c_size_t), ("nonmanifold_edges", ctypes.c_size_t),
        ("mesh_volume", ctypes.c_double), ("inconsistent_edges", ctypes.c_size_t),
        ("mesh_pieces", ctypes.c_size_t), ("inside", _e),
        ("duplicate_triangles", ctypes.c_size_t), ("opposite_triangles", ctypes.c_size_t),
        ("reoriented_triangles", ctypes.c_size_t), ("turned_pieces", ctypes.c_size_t),
        ("cavities", ctypes.c_size_t), ("volume_estimate_kind", _e),
        ("volume_estimate", ctypes.c_double), ("volume_mismatch", ctypes.c_int),
        ("iso", ctypes.c_double)]


class vp_container_params(ctypes.Structure):
    _fields_ = [
        ("voxel_size", ctypes.c_double), ("particle_radius", ctypes.c_double),
        ("particle_count", ctypes.c_size_t), ("space_per_particle", ctypes.c_double),
        ("inside", _e), ("grid_name", ctypes.c_char_p), ("has_iso", ctypes.c_int),
        ("iso", ctypes.c_double), ("narrow_band", ctypes.c_int), ("name", ctypes.c_char_p),
        ("extra_depth", ctypes.c_double)]


class vp_shape_ref(ctypes.Structure):
    _fields_ = [("shape", _e), ("param", ctypes.c_double), ("mesh", ctypes.c_void_p)]


class vp_particles(ctypes.Structure):
    _fields_ = [
        ("count", ctypes.c_size_t), ("capacity", ctypes.c_size_t),
        ("positions", ctypes.POINTER(ctypes.c_double)), ("radii", ctypes.POINTER(ctypes.c_float)),
        ("uniform_radius", ctypes.c_float), ("orients", ctypes.POINTER(ctypes.c_float)),
        ("uniform_orient", ctypes.c_float * 4), ("has_orient", ctypes.c_int), ("shape", _e),
        ("mesh", ctypes.c_void_p), ("groups", ctypes.POINTER(ctypes.c_uint16)),
        ("group_count", ctypes.c_uint),
        ("group_names", (ctypes.c_char * VP_GROUP_NAME_MAX) * VP_MAX_GROUPS),
        ("position_error", ctypes.c_double), ("shape_param", ctypes.c_double),
        ("shape_index", ctypes.POINTER(ctypes.c_uint8)), ("shape_count", ctypes.c_uint),
        ("shapes", vp_shape_ref * VP_MAX_SHAPES),
        ("shape_names", (ctypes.c_char * VP_SHAPE_NAME_MAX) * VP_MAX_SHAPES)]


class vp_lattice_params(ctypes.Structure):
    _fields_ = [
        ("shape", _e), ("lattice", _e), ("fit", _e), ("radius", ctypes.c_double),
        ("count", ctypes.c_size_t), ("offsets", ctypes.c_int), ("rotate", ctypes.c_int),
        ("rotations", ctypes.c_int), ("seed", ctypes.c_uint64), ("shape_param", ctypes.c_double),
        ("margin", ctypes.c_double), ("gap", ctypes.c_double)]


class vp_lattice_report(ctypes.Structure):
    _fields_ = [
        ("radius", ctypes.c_double), ("count", ctypes.c_size_t), ("offsets_tried", ctypes.c_int),
        ("rotations_tried", ctypes.c_int), ("radius_iterations", ctypes.c_int),
        ("offset", c_double3), ("rotation", c_double4), ("lattice_fraction", ctypes.c_double),
        ("particle_volume", ctypes.c_double), ("seconds", ctypes.c_double)]


class vp_meta(ctypes.Structure):
    _fields_ = [("key", ctypes.c_char_p), ("type", _e), ("s", ctypes.c_char_p),
                ("i", ctypes.c_int64), ("d", ctypes.c_double)]


class vp_write_report(ctypes.Structure):
    _fields_ = [
        ("full_precision", ctypes.c_int), ("promoted", ctypes.c_int),
        ("voxel_size", ctypes.c_double), ("position_error", ctypes.c_double),
        ("fixed16_error", ctypes.c_double), ("min_radius", ctypes.c_double)]


class vp_write_params(ctypes.Structure):
    _fields_ = [
        ("full_precision", ctypes.c_int), ("points_per_voxel", ctypes.c_int),
        ("meta", ctypes.POINTER(vp_meta)), ("meta_count", ctypes.c_size_t),
        ("report", ctypes.POINTER(vp_write_report)), ("max_memory", ctypes.c_uint64)]


class vp_size_dist(ctypes.Structure):
    _fields_ = [("kind", _e), ("a", ctypes.c_double), ("b", ctypes.c_double),
                ("n", ctypes.c_uint), ("values", ctypes.c_double * VP_SIZE_LIST_MAX)]


class vp_rsa_pass(ctypes.Structure):
    _fields_ = [
        ("count", ctypes.c_size_t), ("maximal", ctypes.c_int), ("radius", vp_size_dist),
        ("retries", ctypes.c_int), ("grow", ctypes.c_int),
        ("name", ctypes.c_char * VP_GROUP_NAME_MAX), ("own_shape", ctypes.c_int),
        ("shape", vp_shape_ref)]


class vp_rsa_params(ctypes.Structure):
    _fields_ = [
        ("fit", _e), ("shape", _e), ("mesh", ctypes.c_void_p), ("orient", _e), ("overlap", _e),
        ("passes", ctypes.POINTER(vp_rsa_pass)), ("npasses", ctypes.c_size_t),
        ("seed", ctypes.c_uint64), ("max_cells", ctypes.c_size_t),
        ("shape_param", ctypes.c_double), ("margin", ctypes.c_double), ("gap", ctypes.c_double),
        ("radius_field", ctypes.c_void_p), ("radius_field_mode", _e),
        ("density_field", ctypes.c_void_p)]


class vp_field_info(ctypes.Structure):
    _fields_ = [
        ("bmin", ctypes.c_double * 3), ("bmax", ctypes.c_double * 3),
        ("voxel_size", ctypes.c_double), ("min", ctypes.c_double), ("max", ctypes.c_double),
        ("grid_name", ctypes.c_char * 128)]


class vp_rsa_pass_report(ctypes.Structure):
    _fields_ = [
        ("requested", ctypes.c_size_t), ("placed", ctypes.c_size_t), ("stop", _e),
        ("tries", ctypes.c_uint64), ("pretested", ctypes.c_uint64), ("budget_hit", ctypes.c_int),
        ("grow_mean", ctypes.c_double), ("seconds", ctypes.c_double)]


class vp_rsa_report(ctypes.Structure):
    _fields_ = [
        ("npasses", ctypes.c_size_t), ("passes", vp_rsa_pass_report * VP_MAX_GROUPS),
        ("particle_volume", ctypes.c_double), ("seconds", ctypes.c_double)]


class vp_relax_params(ctypes.Structure):
    _fields_ = [
        ("fit", _e), ("radius", vp_size_dist), ("count", ctypes.c_size_t),
        ("target_fraction", ctypes.c_double), ("tolerance", ctypes.c_double),
        ("max_sweeps", ctypes.c_int), ("seed", ctypes.c_uint64),
        ("margin", ctypes.c_double), ("gap", ctypes.c_double),
        ("radius_field", ctypes.c_void_p), ("radius_field_mode", _e)]


class vp_relax_report(ctypes.Structure):
    _fields_ = [
        ("count", ctypes.c_size_t), ("sweeps", ctypes.c_int), ("radius_scale", ctypes.c_double),
        ("initial_fraction", ctypes.c_double), ("max_overlap", ctypes.c_double),
        ("particle_volume", ctypes.c_double), ("seconds", ctypes.c_double)]


class vp_jam_params(ctypes.Structure):
    _fields_ = [
        ("fit", _e), ("radius", vp_size_dist), ("count", ctypes.c_size_t),
        ("target_fraction", ctypes.c_double), ("tolerance", ctypes.c_double),
        ("contact_gap", ctypes.c_double), ("seed", ctypes.c_uint64),
        ("margin", ctypes.c_double), ("gap", ctypes.c_double),
        ("radius_field", ctypes.c_void_p), ("radius_field_mode", _e)]


class vp_jam_report(ctypes.Structure):
    _fields_ = [
        ("count", ctypes.c_size_t), ("fraction", ctypes.c_double),
        ("core_fraction", ctypes.c_double), ("core_count", ctypes.c_size_t),
        ("core_volume", ctypes.c_double), ("mean_contacts", ctypes.c_double),
        ("rattler_fraction", ctypes.c_double), ("max_overlap", ctypes.c_double),
        ("radius_scale", ctypes.c_double), ("particle_volume", ctypes.c_double),
        ("minimizations", ctypes.c_int), ("iterations", ctypes.c_long),
        ("list_builds", ctypes.c_int), ("seconds", ctypes.c_double)]


class vp_check_params(ctypes.Structure):
    _fields_ = [
        ("fit", _e), ("overlap_tolerance", ctypes.c_double),
        ("contact_tolerance", ctypes.c_double), ("wall_tolerance", ctypes.c_double),
        ("position_tolerance", ctypes.c_double), ("margin", ctypes.c_double),
        ("gap", ctypes.c_double)]


class vp_check_report(ctypes.Structure):
    _fields_ = [
        ("count", ctypes.c_size_t), ("overlapping_pairs", ctypes.c_size_t),
        ("max_overlap", ctypes.c_double), ("max_overlap_world", ctypes.c_double),
        ("outside", ctypes.c_size_t), ("max_outside", ctypes.c_double),
        ("particle_volume", ctypes.c_double), ("container_volume", ctypes.c_double),
        ("fraction", ctypes.c_double), ("mean_contacts", ctypes.c_double),
        ("contact_pairs", ctypes.c_size_t), ("position_error_ratio", ctypes.c_double),
        ("imprecise", ctypes.c_int), ("seconds", ctypes.c_double)]


class vp_render_params(ctypes.Structure):
    _fields_ = [
        ("width", ctypes.c_int), ("height", ctypes.c_int), ("view", _e), ("eye", c_double3),
        ("target", c_double3), ("up", c_double3), ("fov_degrees", ctypes.c_double),
        ("colour", _e), ("cut_axis", ctypes.c_int), ("cut_value", ctypes.c_double),
        ("ao_samples", ctypes.c_int), ("shadows", ctypes.c_int)]


class vp_image(ctypes.Structure):
    _fields_ = [
        ("width", ctypes.c_int), ("height", ctypes.c_int),
        ("rgba", ctypes.POINTER(ctypes.c_float)), ("z", ctypes.POINTER(ctypes.c_float)),
        ("id", ctypes.POINTER(ctypes.c_uint32))]


class vp_export_params(ctypes.Structure):
    _fields_ = [("format", _e), ("vdb", vp_write_params), ("sphere_subdivisions", ctypes.c_int)]


# every mirrored struct, for the layout test
STRUCTS = (vp_container_ops, vp_container_info, vp_container_params, vp_shape_ref, vp_particles,
           vp_lattice_params, vp_lattice_report, vp_meta, vp_write_report, vp_write_params,
           vp_size_dist, vp_field_info, vp_rsa_pass, vp_rsa_params, vp_rsa_pass_report, vp_rsa_report,
           vp_relax_params, vp_relax_report, vp_jam_params, vp_jam_report, vp_check_params,
           vp_check_report, vp_render_params, vp_image, vp_export_params)

# ---------------------------------------------------------------------------
# Prototypes

_P = ctypes.POINTER
_vp = ctypes.c_void_p
_res = ctypes.c_int
_d = ctypes.c_double
_s = ctypes.c_char_p
_z = ctypes.c_size_t


def _proto(name, restype, *argtypes):
    try:
        f = getattr(lib, name)
    except AttributeError:
        raise ImportError("vdbpack: %s has no function %s: it is not a vdbpack library this "
                          "module can use (set %s to the path of libvdbpack.so)"
                          % (LIBRARY_PATH, name, _ENV)) from None
    f.restype = restype
    f.argtypes = list(argtypes)


for _name, _r, _a in [
        ("vp_version", _s, ()),
        ("vp_version_number", ctypes.c_int, ()),
        ("vp_result_name", _s, (_res,)),
        ("vp_context_create", _res, (_P(_vp),)),
        ("vp_context_destroy", None, (_vp,)),
        ("vp_context_message", _s, (_vp,)),
        ("vp_context_set_threads", None, (_vp, ctypes.c_int)),
        ("vp_context_set_progress", None, (_vp, PROGRESS_FN, _vp)),
        ("vp_context_set_max_memory", None, (_vp, ctypes.c_uint64)),
        ("vp_shape_name", _s, (_e,)),
        ("vp_shape_parse", ctypes.c_int, (_s, _P(_e))),
        ("vp_shape_unit_volume", _d, (_e,)),
        ("vp_shape_write_obj", _res, (_vp, _e, _s)),
        ("vp_shape_parse_param", ctypes.c_int, (_s, _P(_e), _P(_d))),
        ("vp_shape_format", _s, (_e, _d, _s, _z)),
        ("vp_shape_unit_volume_param", _d, (_e, _d)),
        ("vp_shape_write_obj_param", _res, (_vp, _e, _d, _s)),
        ("vp_mesh_shape_load", _res, (_vp, _s, _P(_vp))),
        ("vp_mesh_shape_destroy", None, (_vp,)),
        ("vp_mesh_shape_volume", _d, (_vp,)),
        ("vp_mesh_shape_inradius", _d, (_vp,)),
        ("vp_mesh_shape_triangles", _z, (_vp,)),
        ("vp_mesh_shape_name", _s, (_vp,)),
        ("vp_mesh_shape_from_mesh", _res, (_vp, _s, _vp, _z, _vp, _z, _P(_vp))),
        ("vp_mesh_shape_write_obj", _res, (_vp, _vp, _s)),
        ("vp_shape_mesh", _res, (_vp, _e, _d, _vp, _vp, _P(_z), _vp, _P(_z), _vp, _P(_z))),
        ("vp_container_create_sphere", _res, (_vp, c_double3, _d, _P(_vp))),
        ("vp_container_create_box", _res, (_vp, c_double3, c_double3, _P(_vp))),
        ("vp_container_create_custom", _res,
         (_vp, _P(vp_container_ops), _vp, c_double3, c_double3, _d, _P(_vp))),
        ("vp_container_params_init", None, (_P(vp_container_params),)),
        ("vp_container_load", _res, (_vp, _s, _P(vp_container_params), _P(_vp))),
        ("vp_container_from_mesh", _res,
         (_vp, _vp, _z, _vp, _z, _P(vp_container_params), _P(_vp))),
        ("vp_container_destroy", None, (_vp,)),
        ("vp_container_subtract", _res, (_vp, _vp, _vp, _P(_vp))),
        ("vp_field_load", _res, (_vp, _s, _s, _P(_vp))),
        ("vp_field_destroy", None, (_vp,)),
        ("vp_field_get_info", None, (_vp, _P(vp_field_info))),
        ("vp_field_sample", _d, (_vp, _P(_d))),
        ("vp_field_check", _res, (_vp, _vp, _s, _s, ctypes.c_int, _vp, _P(_d), _P(_d))),
        ("vp_container_get_info", None, (_vp, _P(vp_container_info))),
        ("vp_container_distances", None, (_vp, _vp, _z, _vp)),
        ("vp_container_save", _res, (_vp, _vp, _s)),
        ("vp_particles_destroy", None, (_P(vp_particles),)),
        ("vp_particles_volume", _d, (_P(vp_particles),)),
        ("vp_particles_shape_list", _s, (_P(vp_particles), _s, _z)),
        ("vp_particles_write_shapes_obj", _res, (_vp, _P(vp_particles), _s)),
        ("vp_lattice_params_init", None, (_P(vp_lattice_params),)),
        ("vp_lattice_fraction", _d, (_e, _e)),
        ("vp_lattice_fraction_param", _d, (_e, _d, _e)),
        ("vp_pack_lattice", _res,
         (_vp, _vp, _P(vp_lattice_params), _P(_P(vp_particles)), _P(vp_lattice_report))),
        ("vp_container_params_for_lattice", None,
         (_P(vp_container_params), _P(vp_lattice_params))),
        ("vp_write_params_init", None, (_P(vp_write_params),)),
        ("vp_write_points", _res, (_vp, _s, _P(vp_particles), _P(vp_write_params))),
        ("vp_read_points", _res, (_vp, _s, _P(_P(vp_particles)))),
        ("vp_describe_file", _res, (_vp, _s, ctypes.c_int, _P(_vp))),
        ("vp_size_dist_parse", _res, (_vp, _s, _P(vp_size_dist))),
        ("vp_size_dist_min", _d, (_P(vp_size_dist),)),
        ("vp_size_dist_max", _d, (_P(vp_size_dist),)),
        ("vp_size_dist_mean_cube", _d, (_P(vp_size_dist),)),
        ("vp_size_dist_format", None, (_P(vp_size_dist), _s, _z)),
        ("vp_rsa_pass_init", None, (_P(vp_rsa_pass),)),
        ("vp_rsa_params_init", None, (_P(vp_rsa_params),)),
        ("vp_pack_rsa", _res,
         (_vp, _vp, _P(vp_rsa_params), _P(_P(vp_particles)), _P(vp_rsa_report))),
        ("vp_container_params_for_rsa", None, (_P(vp_container_params), _P(vp_rsa_params))),
        ("vp_relax_params_init", None, (_P(vp_relax_params),)),
        ("vp_pack_relax", _res,
         (_vp, _vp, _P(vp_relax_params), _P(_P(vp_particles)), _P(vp_relax_report))),
        ("vp_container_params_for_relax", None, (_P(vp_container_params), _P(vp_relax_params))),
        ("vp_jam_params_init", None, (_P(vp_jam_params),)),
        ("vp_pack_jam", _res,
         (_vp, _vp, _P(vp_jam_params), _P(_P(vp_particles)), _P(vp_jam_report))),
        ("vp_container_params_for_jam", None, (_P(vp_container_params), _P(vp_jam_params))),
        ("vp_check_params_init", None, (_P(vp_check_params),)),
        ("vp_check_particles", _res,
         (_vp, _vp, _P(vp_particles), _P(vp_check_params), _P(vp_check_report))),
        ("vp_render_params_init", None, (_P(vp_render_params),)),
        ("vp_render", _res, (_vp, _P(vp_particles), _P(vp_render_params), _P(_P(vp_image)))),
        ("vp_image_destroy", None, (_P(vp_image),)),
        ("vp_image_write", _res, (_vp, _P(vp_image), _s)),
        ("vp_export_params_init", None, (_P(vp_export_params),)),
        ("vp_export", _res, (_vp, _s, _P(vp_particles), _P(vp_export_params))),
        ("vp_import", _res, (_vp, _s, _e, _P(_P(vp_particles)), _P(ctypes.c_int))),
        ("vp_format_from_path", _e, (_s,)),
]:
    _proto(_name, _r, *_a)

# vp_describe_file's text is malloc'd by the library and freed with free();
# the C library's free is the one libvdbpack uses (the same process).
_libc = ctypes.CDLL(None)
free = _libc.free
free.restype = None
free.argtypes = [ctypes.c_void_p]

VERSION = lib.vp_version().decode()
# The structs above are those of the headers this module was written for:
# the build records their version beside the library's path, and a library
# of another version (through VDBPACK_LIBRARY, say) may lay them out
# differently, so it is refused rather than called.
_expected = getattr(_libpath, "VERSION", None) if _libpath else None
if _expected and _expected != VERSION:
    raise ImportError("vdbpack: this module is version %s but %s is version %s; use the "
                      "library of the same build or installation (unset %s or point it there)"
                      % (_expected, LIBRARY_PATH, VERSION, _ENV))
