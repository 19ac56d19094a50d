/* SPDX-License-Identifier: Apache-2.0 */
/* vdbpack public C API: fill a closed container with non-overlapping
 * particles and write them as OpenVDB points.
 *
 * Conventions (after OpenEXR Core / Embree):
 *  - every call that can fail returns a vp_result; the context keeps a
 *    message for the last failure, valid until the next call on it;
 *  - new objects come back through an out-parameter and are owned by the
 *    caller, who frees them with the matching _destroy(); destroy(NULL) is a
 *    no-op;
 *  - params structs have an _init() that fills defaults; a NULL params
 *    pointer means defaults.
 * Threading: a context and the objects made through it are used by one
 * thread at a time; the library itself uses vp_context_set_threads() worker
 * threads internally and its results do not depend on that number.
 */
#ifndef VDBPACK_VDBPACK_H
#define VDBPACK_VDBPACK_H

#include <stddef.h>
#include <stdint.h>

#include "vdbpack/version.h"

/* VP_API marks the library's exported functions: the shared library is
 * built with hidden visibility, so only what is declared with it in these
 * headers is visible to programs. Define VP_STATIC when linking the static
 * library on Windows. */
#if defined(_WIN32) && !defined(VP_STATIC)
#ifdef VP_BUILDING_LIBRARY
#define VP_API __declspec(dllexport)
#else
#define VP_API __declspec(dllimport)
#endif
#elif defined(__GNUC__) || defined(__clang__)
#define VP_API __attribute__((visibility("default")))
#else
#define VP_API
#endif

#ifdef __cplusplus
extern "C" {
#endif

/* The library's version as "MAJOR.MINOR.PATCH" (VP_VERSION_STRING of the
 * library that was loaded, which may be newer than the headers a program
 * was compiled with). Static; never NULL. */
VP_API const char *vp_version(void);
/* The version as one number, VP_VERSION_NUMBER of the loaded library. */
VP_API int vp_version_number(void);
/* 1 when third-party file readers (Assimp for meshes, OpenVDB for .vdb
 * files) run first in a forked child process, so that their crashes and
 * hangs on a bad file become errors (the product's builds); 0 in fuzzing
 * and AddressSanitizer builds, which read in-process. */
VP_API int vp_readers_isolated(void);

/* ------------------------------------------------------------------ */
/* Results and context                                                 */

typedef enum vp_result {
    VP_OK = 0,
    VP_ERR_INVALID_ARGUMENT, /* a parameter is out of range or malformed */
    VP_ERR_IO,               /* a file could not be read or written */
    VP_ERR_FORMAT,           /* a file is not of the expected kind or is corrupt */
    VP_ERR_OPEN_MESH,        /* the mesh has boundary or non-manifold edges */
    VP_ERR_NOT_LEVEL_SET,    /* a .vdb holds no usable float level set */
    VP_ERR_BAD_CONTAINER,    /* the container is empty or its inside leaks */
    VP_ERR_NO_FIT,           /* no particle fits in the container */
    VP_ERR_OUT_OF_MEMORY,    /* allocation failed or the estimate is too large */
    VP_ERR_CANCELLED,        /* the progress callback asked to stop */
    VP_ERR_INTERNAL          /* a bug: please report it */
} vp_result;

/* Static name of a result ("VP_ERR_IO"); never NULL. */
VP_API const char *vp_result_name(vp_result r);

typedef struct vp_context vp_context;

/* Progress callback: fraction in [0,1] and a short stage name. Return 0 to
 * cancel; the running call then returns VP_ERR_CANCELLED. */
typedef int (*vp_progress_fn)(void *user, double fraction, const char *stage);

/* Creates a context. *out is owned by the caller. */
VP_API vp_result vp_context_create(vp_context **out);
VP_API void vp_context_destroy(vp_context *ctx);
/* Message of the last failure on ctx ("" if none). Owned by ctx, valid
 * until the next call that takes ctx. */
VP_API const char *vp_context_message(const vp_context *ctx);
/* Worker threads for parallel stages; 0 (default) = all cores. */
VP_API void vp_context_set_threads(vp_context *ctx, int threads);
VP_API int vp_context_threads(const vp_context *ctx);
VP_API void vp_context_set_progress(vp_context *ctx, vp_progress_fn fn, void *user);
/* Inside a progress callback: 1, with the particles the current stage has
 * placed so far and the number it aims at (*total 0: none fixed, as a
 * maximal pass), when the stage reports counts (the random packer's
 * passes, per pass); else 0. Either pointer may be NULL. */
VP_API int vp_context_progress_counts(const vp_context *ctx, uint64_t *done, uint64_t *total);
/* Async-signal-safe: removes the temporary files of every write still in
 * progress in this process (outputs are written to a temporary name and
 * renamed). For a signal handler that is about to _exit(); the targets of
 * finished writes are not touched. */
VP_API void vp_remove_partial_outputs(void);
/* The file that a write to path replaces, in out (outlen bytes): path
 * with its symbolic links followed, as the writers follow them. 1 when
 * that is an existing regular file; 0 when there is none or it is not a
 * regular file (a device or FIFO, which writers write through and never
 * replace), or the name does not fit. */
VP_API int vp_output_file(const char *path, char *out, size_t outlen);
/* Removes what a finished write to path left: the regular file it
 * replaced (links followed; the links stay), and nothing that is not a
 * regular file. For a job that fails after some of its outputs were
 * written. */
VP_API void vp_remove_output(const char *path);
/* Memory limit in bytes for estimates (0 = physical memory). */
VP_API void vp_context_set_max_memory(vp_context *ctx, uint64_t bytes);
VP_API uint64_t vp_context_max_memory(const vp_context *ctx);

/* ------------------------------------------------------------------ */
/* Shapes                                                              */

typedef enum vp_shape {
    VP_SHAPE_SPHERE = 0,
    VP_SHAPE_TETRAHEDRON,
    VP_SHAPE_CUBE,
    VP_SHAPE_OCTAHEDRON,
    VP_SHAPE_DODECAHEDRON,
    VP_SHAPE_ICOSAHEDRON,
    /* the 13 Archimedean solids (names in vp_shape_name: "truncated-cube"...) */
    VP_SHAPE_TRUNCATED_TETRAHEDRON,
    VP_SHAPE_CUBOCTAHEDRON,
    VP_SHAPE_TRUNCATED_CUBE,
    VP_SHAPE_TRUNCATED_OCTAHEDRON,
    VP_SHAPE_RHOMBICUBOCTAHEDRON,
    VP_SHAPE_TRUNCATED_CUBOCTAHEDRON,
    VP_SHAPE_SNUB_CUBE,
    VP_SHAPE_ICOSIDODECAHEDRON,
    VP_SHAPE_TRUNCATED_DODECAHEDRON,
    VP_SHAPE_TRUNCATED_ICOSAHEDRON,
    VP_SHAPE_RHOMBICOSIDODECAHEDRON,
    VP_SHAPE_TRUNCATED_ICOSIDODECAHEDRON,
    VP_SHAPE_SNUB_DODECAHEDRON,
    VP_SHAPE_COUNT,          /* the number of built-in shapes above */
    VP_SHAPE_MESH = 64,      /* a closed mesh from a file (vp_mesh_shape) */
    VP_SHAPE_SUPERBALL = 65, /* |x|^2p + |y|^2p + |z|^2p <= 1, convex (0.5 <= p <=
                              1000): p = 1 a sphere, 0.5 an octahedron, large
                              p nearly a cube; p is the shape_param field of
                              the particle set and of the packers' params */
    VP_SHAPE_MIXED = 66      /* a particle set of several shapes (rsa passes of
                              different shapes): vp_particles.shapes names
                              them, vp_particles.shape_index gives each
                              particle's; never a packer's shape */
} vp_shape;

/* A particle shape from a closed mesh (vp_mesh_shape_load, below). */
typedef struct vp_mesh_shape vp_mesh_shape;

/* One particle shape with what it needs: a built-in shape, a superball with
 * its exponent, or a mesh shape. */
typedef struct vp_shape_ref {
    vp_shape shape;
    double param;              /* VP_SHAPE_SUPERBALL: the exponent p; else 0 */
    const vp_mesh_shape *mesh; /* VP_SHAPE_MESH: the shape (not owned); else NULL */
} vp_shape_ref;
/* Most distinct shapes in one particle set, and the longest recorded name
 * of a mesh shape (with its terminating 0) that a set read from a file
 * keeps. */
#define VP_MAX_SHAPES 16
#define VP_SHAPE_NAME_MAX 64

/* "sphere", "cube", ..., "mesh"; NULL for an invalid value. */
VP_API const char *vp_shape_name(vp_shape s);
/* Parses a shape name; returns 0 on success. */
VP_API int vp_shape_parse(const char *name, vp_shape *out);
/* Volume of the shape scaled to bounding-sphere (circum) radius 1. */
VP_API double vp_shape_unit_volume(vp_shape s);
/* Writes the unit shape (circumradius 1, centroid at the origin, in the
 * orientation that `orient` = identity means) as an OBJ file, atomically. */
VP_API vp_result vp_shape_write_obj(vp_context *ctx, vp_shape s, const char *path);

/* Shapes with a parameter (superballs: the exponent p; ignored by the
 * other shapes). Parses a shape as the command line takes it: a built-in
 * name or "superball:P". Returns 0; -1 for an unknown name; -2 for a
 * superball whose P is not a number in [0.5, 1000] (concave superballs,
 * p < 0.5, are not offered). */
VP_API int vp_shape_parse_param(const char *text, vp_shape *out, double *param);
/* The shape as text ("cube", "superball:2"), in buf (size n; always
 * terminated); the name as files record it. Returns buf. */
VP_API const char *vp_shape_format(vp_shape s, double param, char *buf, size_t n);
/* Volume at bounding radius 1 (superballs: the closed form of Jiao et
 * al. 2009 scaled to bounding radius 1; 0 for an invalid shape). */
VP_API double vp_shape_unit_volume_param(vp_shape s, double param);
/* As vp_shape_write_obj (superballs: a closed tessellation whose vertices
 * lie on the surface). */
VP_API vp_result vp_shape_write_obj_param(vp_context *ctx, vp_shape s, double param,
                                          const char *path);

/* A particle shape from a closed mesh file (any format Assimp reads; convex
 * or not), normalised: the centroid of its volume at the origin and its
 * bounding radius about that point 1, so that pscale is the bounding-sphere
 * radius as for the built-in shapes. Immutable once loaded: one shape may
 * serve several threads. Errors: unreadable or unparsable file, an open or
 * non-manifold mesh (VP_ERR_OPEN_MESH, naming the edge counts), a mesh that
 * encloses no volume (VP_ERR_FORMAT). *out is owned by the caller. */
VP_API vp_result vp_mesh_shape_load(vp_context *ctx, const char *path, vp_mesh_shape **out);
VP_API void vp_mesh_shape_destroy(vp_mesh_shape *s);          /* NULL: no-op */
VP_API double vp_mesh_shape_volume(const vp_mesh_shape *s);   /* at bounding radius 1 */
VP_API double vp_mesh_shape_inradius(const vp_mesh_shape *s); /* nearest surface point from the
                                                                 centroid; 0 if it is outside */
VP_API size_t vp_mesh_shape_triangles(const vp_mesh_shape *s);
/* the file's base name; owned by s */
VP_API const char *vp_mesh_shape_name(const vp_mesh_shape *s);
/* The same from a triangle mesh in memory (arrays as for
 * vp_container_from_mesh: 3 * vertex_count doubles, 3 * triangle_count
 * 32-bit indices, only read during the call); name (NULL = "mesh") is what
 * vp_mesh_shape_name returns and what files record. */
VP_API vp_result vp_mesh_shape_from_mesh(vp_context *ctx, const char *name, const double *vertices,
                                         size_t vertex_count, const uint32_t *triangles,
                                         size_t triangle_count, vp_mesh_shape **out);
/* Writes the normalised shape as OBJ (atomically), for instancing. */
VP_API vp_result vp_mesh_shape_write_obj(vp_context *ctx, const vp_mesh_shape *s, const char *path);

/* The unit shape's surface as arrays, for instancing without a file: the
 * vertices and faces that vp_shape_write_obj_param (or, for VP_SHAPE_MESH,
 * vp_mesh_shape_write_obj of mesh) writes: a solid's polygons, a
 * superball's or a mesh shape's triangles, each face counter-clockwise
 * seen from outside. Spheres have none (VP_ERR_INVALID_ARGUMENT). Call it
 * twice: with vertices, face_sizes and indices NULL it sets *nverts,
 * *nfaces and *nindices; then with arrays of 3 * *nverts doubles, *nfaces
 * and *nindices (0-based) uint32 it fills them (counts smaller than the
 * shape's: VP_ERR_INVALID_ARGUMENT, nothing written). */
VP_API vp_result vp_shape_mesh(vp_context *ctx, vp_shape s, double param, const vp_mesh_shape *mesh,
                               double *vertices, size_t *nverts, uint32_t *face_sizes,
                               size_t *nfaces, uint32_t *indices, size_t *nindices);

/* ------------------------------------------------------------------ */
/* Containers                                                          */

typedef struct vp_container vp_container;

/* A container seen through callbacks: how packers see every container. */
typedef struct vp_container_ops {
    /* Signed distance at world point p: negative inside, positive outside.
     * Must be safe to call from several threads at once. */
    double (*distance)(void *user, const double p[3]);
    /* Optional: outward unit gradient of the distance; NULL = central
     * differences. */
    void (*gradient)(void *user, const double p[3], double g[3]);
    /* Optional: frees user when the container is destroyed. */
    void (*destroy)(void *user);
} vp_container_ops;

typedef enum vp_container_kind {
    VP_CONTAINER_ANALYTIC = 0,
    VP_CONTAINER_MESH,
    VP_CONTAINER_LEVEL_SET
} vp_container_kind;

/* How the inside of a mesh container is decided (docs/design.md, "Inside
 * of a mesh"). */
typedef enum vp_inside_mode {
    VP_INSIDE_AUTO = 0, /* closed, consistently oriented meshes of pieces that
                           do not overlap as OpenVDB voxelizes closed surfaces;
                           any other mesh by its winding number */
    VP_INSIDE_CLOSED,   /* closed, consistently oriented meshes only (others
                           are refused with VP_ERR_OPEN_MESH); overlapping
                           or nested pieces by their winding number */
    VP_INSIDE_WINDING   /* every mesh by its generalized winding number:
                           inside where it is at least 0.5 */
} vp_inside_mode;
/* "auto", "closed", "winding"; NULL for an invalid value. */
VP_API const char *vp_inside_name(vp_inside_mode m);
/* Parses an inside mode's name; returns 0 on success. */
VP_API int vp_inside_parse(const char *name, vp_inside_mode *out);

/* How vp_container_info.volume_estimate was found. */
typedef enum vp_volume_estimate {
    VP_ESTIMATE_NONE = 0,    /* no estimate (level sets, analytic containers) */
    VP_ESTIMATE_MESH_VOLUME, /* the mesh's signed volume (closed pieces that
                                do not overlap; cavities count negative) */
    VP_ESTIMATE_WINDING      /* the fraction of a grid of 64 samples along
                                the longest side of the mesh's bounding box
                                (grown by a tenth each way for an open
                                mesh) whose winding number is at least 0.5 */
} vp_volume_estimate;

/* What is known about a container (filled by the library). */
typedef struct vp_container_info {
    vp_container_kind kind;
    double bmin[3], bmax[3]; /* world bounds of the inside */
    double volume;           /* world volume of the inside */
    double voxel_size;       /* 0 for analytic containers */
    double interior_band;    /* depth (world) to which distances are exact
                                 inside; HUGE_VAL for analytic containers */
    char voxel_reason[160];  /* why this voxel size was chosen */
    char grid_name[128];     /* level-set grid name (may be empty) */
    size_t active_voxels;
    /* mesh containers only */
    size_t mesh_vertices;     /* after welding */
    size_t mesh_vertices_raw; /* before welding */
    size_t mesh_triangles;
    size_t boundary_edges;
    size_t nonmanifold_edges;
    double mesh_volume;        /* |signed volume| of the mesh as read */
    size_t inconsistent_edges; /* edges where the two triangles run the same
                                 way (the orientation flips there) */
    size_t mesh_pieces;        /* connected pieces */
    vp_inside_mode inside;     /* how the inside was decided: VP_INSIDE_CLOSED
                                 (OpenVDB's closed-surface voxelization) or
                                 VP_INSIDE_WINDING */
    /* what the winding route mended before counting (0 otherwise) */
    size_t duplicate_triangles;  /* second copies dropped */
    size_t opposite_triangles;   /* triangles dropped with their reverse */
    size_t reoriented_triangles; /* turned to agree with their neighbours */
    size_t turned_pieces;        /* pieces turned the right way out */
    size_t cavities;             /* reversed closed pieces kept as cavities */
    /* an independent estimate of the inside's volume (mesh containers) */
    vp_volume_estimate volume_estimate_kind;
    double volume_estimate;
    int volume_mismatch; /* 1: volume and volume_estimate differ by more
                                 than 5 % of the estimate (the voxel size
                                 loses thin parts, or the mesh is broken in a
                                 way the inside cannot mend) */
    /* fog (density) containers: the iso value the inside was taken at */
    double iso;
} vp_container_info;

/* Analytic containers (exact; for tests and simple jobs). */
VP_API vp_result vp_container_create_sphere(vp_context *ctx, const double center[3], double radius,
                                            vp_container **out);
VP_API vp_result vp_container_create_box(vp_context *ctx, const double bmin[3],
                                         const double bmax[3], vp_container **out);
/* A caller-defined container. user is owned by the container if
 * ops->destroy is set. bounds must enclose the inside. */
VP_API vp_result vp_container_create_custom(vp_context *ctx, const vp_container_ops *ops,
                                            void *user, const double bmin[3], const double bmax[3],
                                            double volume, vp_container **out);

typedef struct vp_container_params {
    double voxel_size;         /* 0 = automatic */
    double particle_radius;    /* largest particle bounding radius (world);
                                 sizes the interior band and the auto voxel
                                 size; 0 = unknown (use particle_count) */
    size_t particle_count;     /* expected count when the radius is unknown */
    double space_per_particle; /* with particle_count: volume one particle of
                                 bounding radius 1 takes up in the packing
                                 (shape volume / packing fraction);
                                 0 = spheres on FCC */
    vp_inside_mode inside;     /* meshes: how the inside is decided (default
                                 VP_INSIDE_AUTO) */
    const char *grid_name;     /* .vdb: grid to use; NULL = the first float
                                 level set (or, with has_iso, the first float
                                 grid) */
    int has_iso;               /* .vdb: 1 to take a fog or density grid as the
                                 container: inside where its value >= iso
                                 (Houdini's convention for fog to SDF),
                                 converted to a level set by OpenVDB */
    double iso;
    int narrow_band;    /* 1: the interior band reaches just past
                                 particle_radius (1.02 r + 0.9 voxel, at
                                 least 3 voxels): enough for the lattice
                                 packer, whose search reads deeper through
                                 a coarse depth map, and about a third
                                 faster to voxelize; 0: 1.25 r + 2 voxels,
                                 room for growth and relaxation */
    const char *name;   /* vp_container_from_mesh: the mesh's name in
                                 messages; NULL = "mesh" */
    double extra_depth; /* the interior band reaches this much deeper
                                 (world; >= 0): a margin kept from the wall
                                 (vp_container_params_for_rsa and _for_jam
                                 set it from theirs); default 0 */
} vp_container_params;
VP_API void vp_container_params_init(vp_container_params *p);

/* Loads a container from a mesh (anything Assimp reads) or a .vdb level
 * set, chosen by content/extension. *out is owned by the caller. A path
 * that is not a regular file (a FIFO, a device, a directory) gives
 * VP_ERR_IO at once. The readers run in child processes (see
 * vp_readers_isolated) bounded by the context's memory limit and cancelled
 * through its progress callback. A mesh of any scale loads (too small a
 * voxel for OpenVDB's transforms is handled in scaled units). */
VP_API vp_result vp_container_load(vp_context *ctx, const char *path,
                                   const vp_container_params *params, vp_container **out);

/* A container from a triangle mesh in memory, such as a host application's
 * evaluated mesh, without a file: vertices holds 3 * vertex_count doubles
 * (x, y, z in world units), triangles 3 * triangle_count 32-bit indices
 * into them (from 0; counter-clockwise seen from outside, though a closed
 * mesh's inside does not depend on it). Welded, checked and voxelized
 * exactly as a mesh file is by vp_container_load, with the same errors (an
 * open or inconsistently oriented mesh with params->inside VP_INSIDE_CLOSED:
 * VP_ERR_OPEN_MESH; a mesh with no inside: VP_ERR_BAD_CONTAINER; ...), and for the
 * arrays VP_ERR_INVALID_ARGUMENT: a NULL pointer, a pointer not aligned
 * for its type, an index out of range, a non-finite coordinate. The arrays
 * are only read, during the call; params->name names the mesh in messages.
 * *out is owned by the caller. */
VP_API vp_result vp_container_from_mesh(vp_context *ctx, const double *vertices,
                                        size_t vertex_count, const uint32_t *triangles,
                                        size_t triangle_count, const vp_container_params *params,
                                        vp_container **out);
/* For a host that holds an OpenVDB level set in memory: write it to a .vdb
 * (a fast local or RAM disk will do) and load that, or wrap its sampler in
 * vp_container_create_custom (docs/python.md, "Containers from a host"). */

VP_API void vp_container_destroy(vp_container *c);
VP_API double vp_container_distance(const vp_container *c, const double p[3]);
VP_API void vp_container_gradient(const vp_container *c, const double p[3], double g[3]);
VP_API void vp_container_get_info(const vp_container *c, vp_container_info *info);
/* Signed distances at n points (points: 3 * n doubles; out: n doubles, both
 * owned by the caller), as vp_container_distance gives them one by one. */
VP_API void vp_container_distances(const vp_container *c, const double *points, size_t n,
                                   double *out);
/* Writes a level-set container as its own .vdb (atomically). Analytic
 * containers are refused with VP_ERR_INVALID_ARGUMENT, and so is a level
 * set whose voxel is below VP_POINTS_MIN_VOXEL (a .vdb cannot hold it). */
VP_API vp_result vp_container_save(vp_context *ctx, const vp_container *c, const char *path);

/* ------------------------------------------------------------------ */
/* Particles                                                           */

#define VP_MAX_GROUPS 64
#define VP_GROUP_NAME_MAX 32

/* A particle set. All arrays are owned by the set (vp_particles_destroy). */
typedef struct vp_particles {
    size_t count;
    size_t capacity;
    double *positions; /* 3*count world-space centres */
    float *radii;      /* count bounding-sphere radii, or NULL: all uniform_radius */
    float uniform_radius;
    float *orients; /* 4*count unit quaternions (x,y,z,w), or NULL: all uniform_orient */
    float uniform_orient[4];
    int has_orient; /* 0: spheres, no orient attribute */
    vp_shape shape;
    const vp_mesh_shape *mesh; /* the shape when shape == VP_SHAPE_MESH; not owned */
    uint16_t *groups;          /* count group indices, or NULL: all in group 0 */
    unsigned group_count;      /* >= 1 */
    char group_names[VP_MAX_GROUPS][VP_GROUP_NAME_MAX];
    double position_error; /* read from a file: the largest error (world
                               units) of a stored position against the one
                               written, from P's codec (16-bit fixed point:
                               sqrt(3) * voxel / 65535); 0 otherwise */
    double shape_param;    /* VP_SHAPE_SUPERBALL: the exponent p; else 0 */
    /* shape == VP_SHAPE_MIXED only (else shape_index NULL, shape_count 0):
     * the shapes (2..VP_MAX_SHAPES, in the order of the passes that
     * introduced them) and each particle's index into them (owned) */
    uint8_t *shape_index;
    unsigned shape_count;
    vp_shape_ref shapes[VP_MAX_SHAPES];
    /* a mixed set read from a file: each mesh shape's name as the file
     * records it (its mesh is then NULL until the caller attaches one);
     * "" elsewhere */
    char shape_names[VP_MAX_SHAPES][VP_SHAPE_NAME_MAX];
} vp_particles;

VP_API vp_result vp_particles_create(vp_context *ctx, size_t capacity, vp_particles **out);
VP_API void vp_particles_destroy(vp_particles *p);
/* Sum of particle volumes (shape volume times radius cubed). */
VP_API double vp_particles_volume(const vp_particles *p);
/* Particle i's shape: shapes[shape_index[i]] of a mixed set, else the
 * set's shape, shape_param and mesh. */
VP_API vp_shape_ref vp_particles_shape_of(const vp_particles *p, size_t i);
/* A mixed set's shapes as files record them (the "shapes" metadata, the
 * PLY and CSV headers): vp_shape_format of each, a mesh shape as
 * "mesh:NAME" (vp_mesh_shape_name, or "mesh" without its mesh), joined by
 * ';' in shape-index order: "sphere;cube;mesh:rock.obj". Any other set:
 * its one shape. In buf (size n, always terminated); returns buf. */
VP_API const char *vp_particles_shape_list(const vp_particles *p, char *buf, size_t n);
/* Writes the set's unit shapes to one OBJ, atomically: group "shapeK" is
 * shape K (a mixed set's shape index; "shape0" the one shape of another
 * set; spheres as icospheres), for instancing by the points' shape
 * attribute (docs/export.md, "Several shapes"). Mesh shapes need their
 * mesh. */
VP_API vp_result vp_particles_write_shapes_obj(vp_context *ctx, const vp_particles *p,
                                               const char *path);

/* ------------------------------------------------------------------ */
/* Lattice packer                                                      */

typedef enum vp_lattice {
    VP_LATTICE_DEFAULT = 0, /* FCC for spheres, densest lattice for solids */
    VP_LATTICE_SC,
    VP_LATTICE_BCC,
    VP_LATTICE_FCC,
    VP_LATTICE_HCP,
    VP_LATTICE_DENSEST
} vp_lattice;

VP_API const char *vp_lattice_name(vp_lattice l);
VP_API int vp_lattice_parse(const char *name, vp_lattice *out);

typedef enum vp_fit {
    VP_FIT_INSIDE = 0, /* every particle wholly inside (every vertex for polyhedra) */
    VP_FIT_CENTER      /* centre inside */
} vp_fit;

typedef struct vp_lattice_params {
    vp_shape shape;
    vp_lattice lattice;
    vp_fit fit;
    double radius; /* bounding-sphere radius; 0 = from count */
    size_t count;  /* wanted count when radius == 0 */
    int offsets;   /* placement offsets to try; 0 = automatic, 1 = none */
    int rotate;    /* also search orientations */
    int rotations; /* orientations to try with rotate; 0 = automatic */
    uint64_t seed;
    double shape_param; /* VP_SHAPE_SUPERBALL: the exponent p */
    double margin;      /* world distance every particle keeps from the wall
                           (its surface with fit inside, its centre with fit
                           center); default 0 */
    double gap;         /* spheres: world distance between the surfaces of
                           neighbours (the lattice spaced for radius + gap/2);
                           default 0 */
} vp_lattice_params;
VP_API void vp_lattice_params_init(vp_lattice_params *p);

typedef struct vp_lattice_report {
    double radius;           /* radius used */
    size_t count;            /* particles placed */
    int offsets_tried;       /* placements evaluated in total */
    int rotations_tried;     /* orientations searched (1 without rotate) */
    int radius_iterations;   /* count mode: radii tried */
    double offset[3];        /* chosen lattice offset (world) */
    double rotation[4];      /* chosen global rotation (x,y,z,w) */
    double lattice_fraction; /* fraction of the infinite lattice */
    double particle_volume;  /* sum of particle volumes */
    double seconds;
} vp_lattice_report;

/* The packing fraction of the infinite lattice that vp_pack_lattice uses
 * for shape on lattice (VP_LATTICE_DEFAULT resolved as there), or 0 when
 * the combination is not offered. */
VP_API double vp_lattice_fraction(vp_shape shape, vp_lattice lattice);
/* The same for shapes with a parameter (superballs: the densest of the
 * four lattice families of Jiao, Stillinger & Torquato 2009 at p). */
VP_API double vp_lattice_fraction_param(vp_shape shape, double param, vp_lattice lattice);

/* Fills container c. *out is owned by the caller; report may be NULL. */
VP_API vp_result vp_pack_lattice(vp_context *ctx, const vp_container *c,
                                 const vp_lattice_params *params, vp_particles **out,
                                 vp_lattice_report *report);
/* What a mesh or level-set container needs to know of a lattice job
 * before it is loaded: sets cp's particle_radius, particle_count,
 * space_per_particle and narrow_band as the command line does (its other
 * fields are left as they are), so that vp_container_load gives the same
 * level set. Likewise vp_container_params_for_rsa (rsa.h) and
 * vp_container_params_for_relax (relax.h). */
VP_API void vp_container_params_for_lattice(vp_container_params *cp,
                                            const vp_lattice_params *params);

/* ------------------------------------------------------------------ */
/* Output                                                              */

typedef enum vp_meta_type { VP_META_STRING = 0, VP_META_INT, VP_META_DOUBLE } vp_meta_type;

typedef struct vp_meta {
    const char *key;
    vp_meta_type type;
    const char *s;
    int64_t i;
    double d;
} vp_meta;

/* A .vdb stores P as offsets within the points grid's voxels, so a
 * position is exact to within sqrt(3) x the codec's step x the voxel size
 * (the position_error vp_read_points reports). The writer never stores
 * positions whose error exceeds VP_POSITION_ERROR_LIMIT times the smallest
 * radius: where 16-bit fixed point would, it writes float P instead (and
 * says so in the report and the file's metadata); where even float P
 * cannot (OpenVDB's smallest voxel, VP_POINTS_MIN_VOXEL, holds positions
 * only to about 1.5e-12, so radii below about 1.5e-9), the write fails
 * with VP_ERR_INVALID_ARGUMENT and writes nothing. vp_check_particles
 * reports a file above the limit as imprecise (a violation). */
#define VP_POSITION_ERROR_LIMIT 1e-3
/* The smallest voxel size OpenVDB's transforms accept (a scale map's
 * determinant must be at least 3e-15): cbrt(3e-15), rounded up. */
#define VP_POINTS_MIN_VOXEL 1.4423e-5

/* What vp_write_points wrote (filled on success when
 * vp_write_params.report is not NULL). */
typedef struct vp_write_report {
    int full_precision;    /* 1: float P was written; 0: 16-bit fixed point */
    int promoted;          /* 1: 16-bit fixed point was asked for but would
                                have rounded positions by more than
                                VP_POSITION_ERROR_LIMIT of the smallest
                                radius, so float P was written */
    double voxel_size;     /* the points grid's voxel size */
    double position_error; /* sqrt(3) x step x voxel: what a reader gets */
    double fixed16_error;  /* the error 16-bit fixed point would have had */
    double min_radius;     /* the smallest radius written */
} vp_write_report;

typedef struct vp_write_params {
    int full_precision;   /* 1: float P; 0: 16-bit fixed point (float
                                instead where that is too coarse, see
                                VP_POSITION_ERROR_LIMIT) */
    int points_per_voxel; /* for OpenVDB's voxel-size helper; default 8 */
    const vp_meta *meta;  /* file metadata; may be NULL */
    size_t meta_count;
    vp_write_report *report; /* may be NULL; owned by the caller, filled on
                                success */
    uint64_t max_memory;     /* bytes: a points grid whose OpenVDB tree is
                                estimated above it is refused
                                (VP_ERR_OUT_OF_MEMORY) before it is built;
                                0 in vp_write_points: the context's limit */
} vp_write_params;
VP_API void vp_write_params_init(vp_write_params *p);

/* The smallest radius a .vdb can hold at VP_POSITION_ERROR_LIMIT for
 * positions up to max_coordinate (world, absolute) from the origin: float
 * P in the smallest voxel OpenVDB allows (about 1.5e-9 near the origin),
 * or in the voxel that keeps index coordinates within range far from it. */
VP_API double vp_points_min_radius(double max_coordinate);

/* Writes a PointDataGrid "points" to path (atomically). A position,
 * radius or orient that is not finite is refused (VP_ERR_INVALID_ARGUMENT,
 * naming the particle; nothing written). */
VP_API vp_result vp_write_points(vp_context *ctx, const char *path, const vp_particles *p,
                                 const vp_write_params *params);
/* Reads the "points" grid of a file written by vp_write_points (or any
 * PointDataGrid with P and optionally pscale, orient). A position, pscale
 * or orient that is not finite gives VP_ERR_FORMAT naming the particle; a
 * path that is not a regular file, VP_ERR_IO at once. */
VP_API vp_result vp_read_points(vp_context *ctx, const char *path, vp_particles **out);
/* Describes every grid and the metadata of a .vdb; *out is malloc'd text
 * (JSON if json != 0) owned by the caller (free()). */
VP_API vp_result vp_describe_file(vp_context *ctx, const char *path, int json, char **out);

/* Per-topic parts of the API. */
#include "vdbpack/size_dist.h"
#include "vdbpack/field.h"
#include "vdbpack/rsa.h"
#include "vdbpack/relax.h"
#include "vdbpack/jam.h"
#include "vdbpack/check.h"
#include "vdbpack/render.h"
#include "vdbpack/export.h"

#ifdef __cplusplus
}
#endif
#endif
