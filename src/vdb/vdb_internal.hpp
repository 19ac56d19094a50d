// SPDX-License-Identifier: Apache-2.0
// Private helpers shared by the src/vdb/*.cpp files (the only C++ layer).
// Not part of any public interface.
#ifndef VDBPACK_VDB_INTERNAL_HPP
#define VDBPACK_VDB_INTERNAL_HPP

#include "vdb/vdb_bridge.h"

#include <openvdb/openvdb.h>
#include <openvdb/io/File.h>

#include <cstdint>
#include <new>
#include <string>
#include <vector>

// A level set owned by the C side. `gen` is unique over the process lifetime
// (a new one whenever `grid` is replaced), so per-thread accessor caches
// keyed by it never see a freed or replaced tree.
struct vpv_levelset {
    openvdb::FloatGrid::Ptr grid;
    uint64_t gen = 0;
    bool affine = false;      // world->index through w2i
    openvdb::math::Mat4d w2i; // row-vector convention (v * M)
    double voxel = 1.0;       // smallest voxel edge (world)
    // World units per unit of the grid (a power of two; 1 but for meshes):
    // OpenVDB's transforms refuse voxels below about 1.44e-5 ("Non-zero
    // scale values required"), so a mesh whose voxel is outside
    // [2^-10, 2^10] is voxelized scaled by 1/scale. The grid's transform,
    // values and background are in its own units; every vpv_levelset_*
    // function takes and returns world units (w2i includes the scale).
    double scale = 1.0;
    // The volume is measured by the smeared Heaviside of every voxel
    // (vdb_levelset_ops.cpp) rather than OpenVDB's levelSetVolume, whose
    // surface integral is off (by about 5 % for a box missing a face) where
    // the winding-number route's film makes the values only close to a
    // distance.
    bool heaviside_volume = false;
    double ensured_depth = 0.0; // ensure_interior already satisfied to this depth
    mutable double band = -1.0; // interior band of grid (a walk of every voxel),
                                // measured on first use; -1: not yet
};

namespace vpv {

// What a failing entry point was doing, for mapping exceptions to codes.
enum class Op { Read, Write, Compute };

// Formats a one-line message (newlines replaced, no trailing newline) into
// err and returns code.
int fail(char *err, size_t errlen, int code, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 4, 5)))
#endif
    ;

// Clears err (err[0] = 0) when there is room.
void clear(char *err, size_t errlen);

// Maps the exception in flight (call from a catch block) to a code and a
// message naming path (may be NULL).
int from_exception(const char *path, Op op, char *err, size_t errlen);

// > 0 while this thread is inside guard(): OpenVDB's failed assertions
// throw instead of aborting (vdb_assert.cpp).
extern thread_local int guard_depth;

// Runs f() (returning an int code) and turns any exception, and any failed
// OpenVDB assertion on this thread, into a code.
template <typename F> int guard(const char *path, Op op, char *err, size_t errlen, F &&f) noexcept
{
    struct depth {
        depth() { ++guard_depth; }
        ~depth() { --guard_depth; }
    } in_guard;
    try {
        return f();
    } catch (...) {
        return from_exception(path, op, err, errlen);
    }
}

// VP_OK if path can be created/truncated for writing, else VP_ERR_IO.
int check_writable(const char *path, char *err, size_t errlen);

// Opens an io::File for reading (no delayed loading), mapping failures to
// VP_ERR_IO ("path: cannot open file (reason)": missing, unreadable, a
// directory) / VP_ERR_FORMAT (shorter than any complete .vdb, or what
// OpenVDB throws).
int open_file(const char *path, openvdb::io::File &file, char *err, size_t errlen);

// open_file, then every grid's metadata into *metas (no voxels read); a
// file without grids fails with none_code ("path: the file holds no
// grids"), the result each reader gives for a file it cannot use.
int read_grid_metadata(const char *path, openvdb::io::File &file, int none_code,
                       openvdb::GridPtrVecPtr &metas, char *err, size_t errlen);

// "level set", "fog volume", ...
std::string class_name(const openvdb::GridBase &g);
// "float", "double", "points", "vec3s", ...
std::string value_type_name(const openvdb::GridBase &g);
// "'density' [fog volume, float], '' [level set, float]"
std::string list_grids(const openvdb::GridPtrVec &grids);

// Writes grids and file metadata to path as io::File would (seekable, Blosc
// and active-mask compression), but through a stream whose every failure is
// checked: io::File::write ignores a short write (disk full, RLIMIT_FSIZE),
// which would leave a truncated file that looks written. Then makes the file
// deterministic (below).
int write_vdb_checked(const char *path, const openvdb::GridCPtrVec &grids,
                      const openvdb::MetaMap &meta, char *err, size_t errlen);

// Replaces the random UUID OpenVDB writes into the file header with a hash
// of the rest of the file, so that equal content gives byte-identical files.
int make_deterministic(const char *path, char *err, size_t errlen);

// File/grid metadata from vp_meta entries.
void fill_meta(openvdb::MetaMap &map, const vp_meta *meta, size_t count, bool for_grid);

// Sets gen/affine/w2i/voxel after grid changed.
void refresh_levelset(vpv_levelset &ls);

uint64_t next_generation();

// OpenVDB 10's fast sweeping (fogToSdf, sdfToSdf, dilateSdf) takes a
// neighbour whose value is 1000 or more, in world units, for one it has
// not reached (FastSweeping.h, NN::operator bool): with voxels of a few
// hundred units its sweeps stopped after a few voxels. Sweeps run on a
// copy made by in_voxel_units (a unit voxel; the values, when they are
// distances, divided by g's voxel size), and to_world_units turns the
// result back (values times h, transform xf).
openvdb::FloatGrid::Ptr in_voxel_units(const openvdb::FloatGrid &g, bool distances);
void to_world_units(openvdb::FloatGrid &g, double h, const openvdb::math::Transform &xf);

} // namespace vpv

#endif
