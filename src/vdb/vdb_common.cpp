// SPDX-License-Identifier: Apache-2.0
// Shared plumbing of the C++ layer: initialisation, messages, exception
// mapping, file checks, metadata and deterministic output.
// OpenVDB's own log messages (log4cplus, e.g. "WARN: f.vdb has more than one
// grid named ...") would be a second line on stderr: vpv_init turns them
// off; vdbpack reports every problem itself. (CMakeLists.txt defines
// OPENVDB_USE_LOG4CPLUS for every file of this layer.)
#include "vdb/vdb_internal.hpp"
#include "os/text.h"

#include <openvdb/util/logging.h>

#include <openvdb/points/PointDataGrid.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <mutex>
#include <sys/stat.h>

extern "C" void vpv_init(void)
{
    static std::once_flag once;
    try {
        std::call_once(once, [] {
            openvdb::initialize();
            openvdb::logging::setLevel(openvdb::logging::Level::Fatal);
        });
    } catch (...) {
        // openvdb::initialize() does not throw in practice; nothing to report.
    }
}

extern "C" int vpv_quiesce_threads(void)
{
    try {
        tbb::task_scheduler_handle h{tbb::attach{}};
        return tbb::finalize(h, std::nothrow) ? 0 : -1;
    } catch (...) {
        return -1;
    }
}

namespace vpv {

void clear(char *err, size_t errlen)
{
    if (err && errlen) err[0] = '\0';
}

int fail(char *err, size_t errlen, int code, const char *fmt, ...)
{
    if (err && errlen) {
        va_list ap;
        va_start(ap, fmt);
        vp_os_vformat(err, errlen, fmt, ap); // a long path loses its middle, not the end
        va_end(ap);
        // one line, and a run of blanks as one (a corrupt file's grid type
        // can be a thousand spaces, which OpenVDB's message quotes)
        char *w = err;
        for (const char *c = err; *c; ++c) {
            char ch = (*c == '\n' || *c == '\r' || *c == '\t') ? ' ' : *c;
            if (ch == ' ' && w > err && w[-1] == ' ') continue;
            *w++ = ch;
        }
        *w = '\0';
        size_t n = strlen(err);
        while (n > 0 && err[n - 1] == ' ') err[--n] = '\0';
    }
    return code;
}

static const char *nm(const char *path) { return path ? path : "(no file)"; }

int from_exception(const char *path, Op op, char *err, size_t errlen)
{
    try {
        throw;
    } catch (const std::bad_alloc &) {
        if (op == Op::Read)
            return fail(err, errlen, VP_ERR_OUT_OF_MEMORY,
                        "%s: out of memory while reading (the file may also be corrupt)", nm(path));
        return fail(err, errlen, VP_ERR_OUT_OF_MEMORY, "%s: out of memory", nm(path));
    } catch (const openvdb::IoError &e) {
        if (op == Op::Write)
            return fail(err, errlen, VP_ERR_IO, "%s: cannot write file (%s)", nm(path), e.what());
        if (op == Op::Read)
            return fail(err, errlen, VP_ERR_FORMAT, "%s: not a readable .vdb file (%s)", nm(path),
                        e.what());
        return fail(err, errlen, VP_ERR_INTERNAL, "%s: %s", nm(path), e.what());
    } catch (const openvdb::Exception &e) {
        if (op == Op::Read)
            return fail(err, errlen, VP_ERR_FORMAT, "%s: not a readable .vdb file (%s)", nm(path),
                        e.what());
        if (op == Op::Write)
            return fail(err, errlen, VP_ERR_INVALID_ARGUMENT, "%s: cannot write points (%s)",
                        nm(path), e.what());
        return fail(err, errlen, VP_ERR_INTERNAL, "%s: OpenVDB error (%s)", nm(path), e.what());
    } catch (const std::exception &e) {
        if (op == Op::Read)
            return fail(err, errlen, VP_ERR_FORMAT, "%s: not a readable .vdb file (%s)", nm(path),
                        e.what());
        if (op == Op::Write)
            return fail(err, errlen, VP_ERR_IO, "%s: cannot write file (%s)", nm(path), e.what());
        return fail(err, errlen, VP_ERR_INTERNAL, "%s: unexpected error (%s)", nm(path), e.what());
    } catch (...) {
        if (op == Op::Read)
            return fail(err, errlen, VP_ERR_FORMAT, "%s: not a readable .vdb file (unknown error)",
                        nm(path));
        return fail(err, errlen, VP_ERR_INTERNAL, "%s: unknown internal error", nm(path));
    }
}

int check_writable(const char *path, char *err, size_t errlen)
{
    if (!path || !*path) return fail(err, errlen, VP_ERR_INVALID_ARGUMENT, "no file name given");
    FILE *f = fopen(path, "wb");
    if (!f)
        return fail(err, errlen, VP_ERR_IO, "%s: cannot write file (%s)", path, strerror(errno));
    fclose(f);
    return VP_OK;
}

// The shortest complete .vdb (header, no metadata, no grids) has 65 bytes;
// OpenVDB reads a shorter one as "no grids" without complaint.
static constexpr size_t kMinVdbBytes = 65;

namespace {
// io::Archive's header reader is protected: this gives it to check_extent.
class HeaderReader : public openvdb::io::Archive {
  public:
    bool read(std::istream &is)
    {
        readHeader(is);
        setFormatVersion(is);
        setLibraryVersion(is);
        setDataCompression(is);
        return inputHasGridOffsets();
    }
};
} // namespace

// Reads the header, the file metadata and each grid's descriptor (never a
// tree) and checks that every grid's recorded offsets lie within the file.
// io::File seeks to those offsets without checking them, and on a file cut
// short its reader can then loop on a failed stream for minutes (a .vdb cut
// at 5000 bytes did) or report "0 active voxels" as if the grid were empty.
static int check_extent(const char *path, uint64_t size, char *err, size_t errlen)
{
    std::ifstream is(path, std::ios::binary);
    if (!is)
        return fail(err, errlen, VP_ERR_IO, "%s: cannot open file (%s)", path, strerror(errno));
    HeaderReader header;
    if (!header.read(is)) return VP_OK; // files before format 212 record no offsets
    openvdb::MetaMap meta;
    meta.readMeta(is);
    int32_t count = -1;
    is.read(reinterpret_cast<char *>(&count), sizeof count);
    if (!is || count < 0)
        return fail(err, errlen, VP_ERR_FORMAT,
                    "%s: not a readable .vdb file (truncated or corrupt before its grid list, "
                    "%llu bytes)",
                    path, (unsigned long long)size);
    for (int32_t i = 0; i < count; ++i) {
        openvdb::io::GridDescriptor gd;
        gd.read(is);
        const int64_t pos = gd.getGridPos(), block = gd.getBlockPos(), end = gd.getEndPos();
        const std::string plain = openvdb::io::GridDescriptor::stripSuffix(gd.uniqueName());
        const std::string name =
            plain.empty() ? std::to_string(i + 1) + " (unnamed)" : "'" + plain + "'";
        if (!is)
            return fail(err, errlen, VP_ERR_FORMAT,
                        "%s: not a readable .vdb file (truncated or corrupt in the description "
                        "of grid %d of %d, %llu bytes)",
                        path, i + 1, count, (unsigned long long)size);
        if (end > 0 && (uint64_t)end > size)
            return fail(err, errlen, VP_ERR_FORMAT,
                        "%s: not a readable .vdb file (truncated: grid %s ends at byte %lld, "
                        "the file has %llu bytes)",
                        path, name.c_str(), (long long)end, (unsigned long long)size);
        if (pos < 0 || block < pos || end < block)
            return fail(err, errlen, VP_ERR_FORMAT,
                        "%s: not a readable .vdb file (corrupt offsets of grid %s: %lld, %lld, "
                        "%lld)",
                        path, name.c_str(), (long long)pos, (long long)block, (long long)end);
        gd.seekToEnd(is);
    }
    return VP_OK;
}

int read_grid_metadata(const char *path, openvdb::io::File &file, int none_code,
                       openvdb::GridPtrVecPtr &metas, char *err, size_t errlen)
{
    int rc = open_file(path, file, err, errlen);
    if (rc != VP_OK) return rc;
    metas = file.readAllGridMetadata();
    if (!metas || metas->empty())
        return fail(err, errlen, none_code, "%s: the file holds no grids", path);
    return VP_OK;
}

int open_file(const char *path, openvdb::io::File &file, char *err, size_t errlen)
{
    if (!path || !*path) return fail(err, errlen, VP_ERR_INVALID_ARGUMENT, "no file name given");
    FILE *f = fopen(path, "rb");
    if (!f) return fail(err, errlen, VP_ERR_IO, "%s: cannot open file (%s)", path, strerror(errno));
    struct stat st;
    const bool have_size = fstat(fileno(f), &st) == 0;
    if (have_size && S_ISDIR(st.st_mode)) {
        fclose(f);
        return fail(err, errlen, VP_ERR_IO, "%s: cannot open file (%s)", path, strerror(EISDIR));
    }
    unsigned char head[kMinVdbBytes];
    size_t got = fread(head, 1, sizeof head, f);
    fclose(f);
    int32_t magic = 0;
    if (got >= 4) std::memcpy(&magic, head, 4);
    if (got < sizeof head)
        return fail(err, errlen, VP_ERR_FORMAT,
                    magic == openvdb::OPENVDB_MAGIC
                        ? "%s: not a readable .vdb file (truncated: %zu bytes, shorter than "
                          "any complete .vdb)"
                        : "%s: not a readable .vdb file (%zu bytes, not a VDB file)",
                    path, got);
    try {
        int rc = check_extent(path, have_size ? (uint64_t)st.st_size : UINT64_MAX, err, errlen);
        if (rc != VP_OK) return rc;
        file.open(/*delayLoad=*/false);
    } catch (...) {
        return from_exception(path, Op::Read, err, errlen);
    }
    return VP_OK;
}

std::string class_name(const openvdb::GridBase &g)
{
    if (g.isType<openvdb::points::PointDataGrid>()) return "points";
    return openvdb::GridBase::gridClassToString(g.getGridClass());
}

std::string value_type_name(const openvdb::GridBase &g)
{
    if (g.isType<openvdb::points::PointDataGrid>()) return "points";
    return g.valueType();
}

std::string list_grids(const openvdb::GridPtrVec &grids)
{
    std::string s;
    for (const auto &g : grids) {
        if (!g) continue;
        if (!s.empty()) s += ", ";
        s += "'" + g->getName() + "' [" + class_name(*g) + ", " + value_type_name(*g) + "]";
    }
    return s;
}

// OpenVDB's header: magic (8), file version (4), library version (4+4),
// has-grid-offsets flag (1), then the UUID as 36 ASCII characters.
int make_deterministic(const char *path, char *err, size_t errlen)
{
    const long uuid_at = 21, uuid_len = 36;
    FILE *f = fopen(path, "r+b");
    if (!f)
        return fail(err, errlen, VP_ERR_IO, "%s: cannot reopen file (%s)", path, strerror(errno));
    unsigned char head[21 + 36];
    if (fread(head, 1, sizeof head, f) != sizeof head || memcmp(head, " BDV", 4) != 0) {
        fclose(f);
        return fail(err, errlen, VP_ERR_IO, "%s: unexpected header after writing", path);
    }
    for (long i = 0; i < uuid_len; ++i) {
        unsigned char c = head[uuid_at + i];
        bool ok = (i == 8 || i == 13 || i == 18 || i == 23) ? c == '-' : isxdigit(c);
        if (!ok) {
            fclose(f);
            return VP_OK;
        } // unknown layout: leave it
    }
    // Two FNV-1a style 64-bit hashes of everything after the UUID, fed 8
    // bytes at a time (a byte at a time took a few tenths of a second on a
    // 100 MB file); the bytes of a partial last word are fed singly.
    uint64_t h1 = 1469598103934665603ull, h2 = 0x9e3779b97f4a7c15ull;
    std::vector<unsigned char> buf(1 << 20);
    size_t n;
    while ((n = fread(buf.data(), 1, buf.size(), f)) > 0) {
        size_t i = 0;
        for (; i + 8 <= n; i += 8) {
            uint64_t w;
            memcpy(&w, buf.data() + i, 8);
            h1 = (h1 ^ w) * 1099511628211ull;
            h2 = (h2 ^ (w >> 7 | w << 57)) * 0x100000001b3ull + 0x632be59bd9b4e019ull;
        }
        for (; i < n; ++i) {
            h1 = (h1 ^ buf[i]) * 1099511628211ull;
            h2 = (h2 ^ buf[i]) * 0x100000001b3ull + 0x632be59bd9b4e019ull;
        }
    }
    if (ferror(f)) {
        fclose(f);
        return fail(err, errlen, VP_ERR_IO, "%s: read error", path);
    }
    char hex[33];
    snprintf(hex, sizeof hex, "%016llx%016llx", (unsigned long long)h1, (unsigned long long)h2);
    hex[12] = '4'; // looks like a version-4 UUID
    char uuid[37];
    snprintf(uuid, sizeof uuid, "%.8s-%.4s-%.4s-%.4s-%.12s", hex, hex + 8, hex + 12, hex + 16,
             hex + 20);
    if (fseek(f, uuid_at, SEEK_SET) != 0 || fwrite(uuid, 1, uuid_len, f) != (size_t)uuid_len) {
        fclose(f);
        return fail(err, errlen, VP_ERR_IO, "%s: cannot write file (%s)", path, strerror(errno));
    }
    if (fclose(f) != 0)
        return fail(err, errlen, VP_ERR_IO, "%s: cannot write file (%s)", path, strerror(errno));
    return VP_OK;
}

namespace {
// Archive::write(std::ostream&, ..., seekable, ...) is protected: this gives
// the checked writer the same format io::File writes.
class CheckedArchive : public openvdb::io::Archive {
  public:
    void writeTo(std::ostream &os, const openvdb::GridCPtrVec &grids,
                 const openvdb::MetaMap &meta) const
    {
        write(os, grids, /*seekable=*/true, meta);
    }
};
} // namespace

int write_vdb_checked(const char *path, const openvdb::GridCPtrVec &grids,
                      const openvdb::MetaMap &meta, char *err, size_t errlen)
{
    std::ofstream os(path, std::ios_base::out | std::ios_base::binary | std::ios_base::trunc);
    if (!os)
        return fail(err, errlen, VP_ERR_IO, "%s: cannot write file (%s)", path, strerror(errno));
    CheckedArchive ar;
    if (openvdb::io::Archive::hasBloscCompression())
        ar.setCompression(openvdb::io::COMPRESS_BLOSC | openvdb::io::COMPRESS_ACTIVE_MASK);
    errno = 0;
    ar.writeTo(os, grids, meta);
    os.flush();
    int e = errno;
    bool ok = bool(os);
    os.close();
    if (!ok || os.fail()) {
        if (!e) e = errno ? errno : EIO;
        return fail(err, errlen, VP_ERR_IO, "%s: writing failed (%s)", path,
                    e == EFBIG ? "file too large: the file-size limit (ulimit -f) was reached"
                               : strerror(e));
    }
    return make_deterministic(path, err, errlen);
}

static bool reserved_grid_key(const std::string &k)
{
    static const char *const keys[] = {"name",
                                       "class",
                                       "creator",
                                       "value_type",
                                       "vector_type",
                                       "is_local_space",
                                       "is_saved_as_half_float",
                                       nullptr};
    for (int i = 0; keys[i]; ++i)
        if (k == keys[i]) return true;
    return k.compare(0, 5, "file_") == 0;
}

void fill_meta(openvdb::MetaMap &map, const vp_meta *meta, size_t count, bool for_grid)
{
    if (!meta) return;
    for (size_t i = 0; i < count; ++i) {
        const vp_meta &m = meta[i];
        if (!m.key || !*m.key) continue;
        std::string key(m.key);
        if (for_grid && reserved_grid_key(key)) continue;
        map.removeMeta(key);
        switch (m.type) {
        case VP_META_STRING: map.insertMeta(key, openvdb::StringMetadata(m.s ? m.s : "")); break;
        case VP_META_INT: map.insertMeta(key, openvdb::Int64Metadata(m.i)); break;
        case VP_META_DOUBLE: map.insertMeta(key, openvdb::DoubleMetadata(m.d)); break;
        default: break;
        }
    }
}

uint64_t next_generation()
{
    static std::atomic<uint64_t> counter{1};
    return counter.fetch_add(1, std::memory_order_relaxed);
}

void refresh_levelset(vpv_levelset &ls)
{
    ls.gen = next_generation();
    ls.ensured_depth = 0.0;
    ls.band = -1.0;
    const openvdb::math::Transform &xf = ls.grid->transform();
    openvdb::Vec3d vs = xf.voxelSize();
    ls.voxel = std::min(vs[0], std::min(vs[1], vs[2]));
    ls.affine = false;
    if (xf.isLinear()) {
        openvdb::math::AffineMap::Ptr a = xf.baseMap()->getAffineMap();
        if (a) {
            const openvdb::math::Mat4d m = a->getMat4();
            ls.w2i = m.inverse();
            ls.affine = true;
            // Edge lengths from the matrix rows: exact even when the
            // translation is large (voxelSize() differences lose bits).
            double v = HUGE_VAL;
            for (int r = 0; r < 3; ++r)
                v = std::min(v,
                             std::sqrt(m(r, 0) * m(r, 0) + m(r, 1) * m(r, 1) + m(r, 2) * m(r, 2)));
            if (v > 0.0 && std::isfinite(v)) ls.voxel = v;
            // world points: divided by the scale (exact, a power of two)
            for (int r = 0; r < 3; ++r)
                for (int c = 0; c < 4; ++c) ls.w2i(r, c) /= ls.scale;
        }
    }
    ls.voxel *= ls.scale;
}

} // namespace vpv
