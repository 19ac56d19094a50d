/* SPDX-License-Identifier: Apache-2.0 */
/* Shared pieces of the command-line tool. */
#ifndef VDBPACK_CLI_CLI_H
#define VDBPACK_CLI_CLI_H

#include <stdint.h>
#include <stdio.h>

/* Prints "vdbpack: <message>" on stderr and returns status. */
int vp_cli_die(int status, const char *fmt, ...)
#ifdef __GNUC__
    __attribute__((format(printf, 2, 3)))
#endif
    ;

/* `vdbpack pack ...` (argv as given to main). */
/* `vdbpack pack --help` (pack_options.c) */
extern const char *VP_PACK_HELP;
int vp_cli_pack(int argc, char **argv);
/* Only the option checks of `vdbpack pack` (and an analytic container's
 * spec): 0, or the exit status after printing one line. For the option
 * fuzzer (fuzz/fuzz_options.c). */
int vp_cli_pack_parse_only(int argc, char **argv);

/* The value options one command line has given: a value option given
 * twice is refused (`-o a.vdb ... -o b.vdb` kept only the last, and a
 * script that appends an option to override another would not be told
 * which one counts). Zero-initialise; aliases (-o and --output, --colour
 * and --color) count as one option. */
#define VP_CLI_SEEN_MAX 48
typedef struct vp_cli_seen {
    const char *opt[VP_CLI_SEEN_MAX];
    const char *value[VP_CLI_SEEN_MAX];
    int n;
} vp_cli_seen;
/* 0 the first time opt is given, else the exit status 2 after one line
 * ("CMD: OPT is given twice ('first' and 'second'); give it once"). */
int vp_cli_once(vp_cli_seen *s, const char *cmd, const char *opt, const char *value);
/* "12 icosahedra", "1 cube", "357 mesh shapes": the count and the shape's
 * noun, in buf (returned). */
int vp_cli_shape_count(char *buf, size_t len, size_t count, int shape);
/* "icosahedra", "mesh shapes", ... */
const char *vp_cli_shape_plural(int shape);
/* 1 when a and b name the same file: the same string; both exist and are
 * the same inode; or they resolve to the same file (links followed, "."
 * and ".." gone; for a file not there yet, its directory resolved and its
 * name, a dangling link at the name followed). */
int vp_cli_same_file(const char *a, const char *b);
/* At start: a standard descriptor (0, 1, 2) that is closed is opened on
 * /dev/null, so that no file or pipe opened later takes its number (and
 * what is printed to it goes nowhere instead of into that file). */
void vp_cli_std_fds(void);
/* After a command's results were printed: when writing the standard output
 * failed (a full disk, /dev/full, a closed pipe), the result asked for is
 * lost, which is an error: one line, and 1 instead of a status 0 or 3
 * (other statuses, errors already told, are returned as they are). Reports
 * once per process. */
int vp_cli_flush_stdout(int status);
/* Strict number parsing: the whole text must be a finite number. */
int vp_cli_parse_double(const char *s, double *out);
int vp_cli_parse_u64(const char *s, uint64_t *out);
/* "8G", "500M", "1024" (bytes). */
int vp_cli_parse_size(const char *s, uint64_t *out);
/* Random packers' options (passes.c); 0 or the exit status after printing
 * one line. */
struct vp_size_dist;
struct vp_rsa_pass;
int vp_cli_parse_sizes(const char *opt, const char *text, struct vp_size_dist *out);
/* Parses one --pass; a shape= that is no built-in name is a mesh file:
 * its name in mesh_file (size mesh_len; "" for the others), loaded by the
 * caller. */
int vp_cli_parse_pass(const char *text, struct vp_rsa_pass *out, char *mesh_file, size_t mesh_len);
/* SIGINT/SIGTERM handling (signals.c). install() once; interrupted() is
 * the signal received (0 if none); track_output() names a finished output
 * to remove if interrupted; done() once every output is final;
 * interrupted_exit() removes the tracked outputs, prints one line and
 * returns the exit status 128 + signal. */
void vp_cli_signals_install(void);
int vp_cli_interrupted(void);
void vp_cli_signals_track_output(const char *path);
void vp_cli_signals_done(void);
int vp_cli_interrupted_exit(void);
/* After the last output `out` of a command was written (failed != 0: its
 * write failed, message on ctx): 0 when the command may report success,
 * else the exit status after one line (the error, or the signal, removing
 * out). */
struct vp_context;
int vp_cli_finish_output(struct vp_context *ctx, int failed, const char *out);
/* sphere:R or box:X,Y,Z (centred at the origin): 1 and *out if spec is
 * one, -1 if malformed, 0 if spec is not analytic (or names a file). */
struct vp_context;
struct vp_container;
int vp_cli_analytic_container(struct vp_context *ctx, const char *spec, struct vp_container **out);
/* `vdbpack check ...` (argv after "check"). */
int vp_cli_check(int argc, char **argv);
/* `vdbpack render ...` (argv after "render"), render.c. */
int vp_cli_render(int argc, char **argv);
/* 0 if path names a .exr or .png, else the exit status after one line
 * naming opt. */
int vp_cli_preview_path_check(const char *opt, const char *path);
/* Renders p with rp (NULL = defaults) and writes path: 0, or 1 with the
 * message left on ctx. */
struct vp_particles;
struct vp_render_params;
int vp_cli_render_particles(struct vp_context *ctx, const struct vp_particles *p,
                            const struct vp_render_params *rp, const char *path);
/* `vdbpack convert IN OUT ...` (argv after "convert"; convert.c). */
int vp_cli_convert(int argc, char **argv);
/* The output format: --format's value if given, else OUT's extension; 0
 * and *out (a vp_format), or 2 after printing one line ("CMD: ..."). */
int vp_cli_output_format(const char *cmd, const char *path, const char *format, int *out);
/* Writes p to path in format (a vp_format) through vp_export, with wp's
 * precision and metadata; for OBJ above VP_CLI_OBJ_WARN_BYTES (estimated)
 * or VP_CLI_OBJ_WARN_COUNT particles, first one warning line on stderr
 * unless quiet. 0, or 1 with the message in ctx. */
#define VP_CLI_OBJ_WARN_BYTES 2e9
#define VP_CLI_OBJ_WARN_COUNT 1000000
struct vp_particles;
struct vp_write_params;
/* After an output was written to path: when that is the standard output
 * itself (-o /dev/stdout, a pipe), what the command prints next (the
 * summary, --json) goes to stderr instead, so the data stays clean. */
void vp_cli_divert_stdout(const char *path);
int vp_cli_write_particles(struct vp_context *ctx, const char *path, int format,
                           const struct vp_particles *p, const struct vp_write_params *wp,
                           int quiet);
/* The summary line for a .vdb whose P was written as float because 16-bit
 * fixed point would have been too coarse (vp_write_report.promoted). */
struct vp_write_report;
void vp_cli_print_promoted(const struct vp_write_report *w);
/* For a packing p read from file by cmd: with a mesh shape, loads
 * shape_files[0] (required; `recorded` is the name the file's metadata
 * gives, or "") into meshes[0] and points p->mesh at it; a mixed set takes
 * one file per mesh shape, in shape-index order. meshes: VP_MAX_SHAPES
 * entries, owned by the caller (NULL where unused). Refuses --shape for
 * other shapes. 0, or the exit status after one line. */
struct vp_particles;
struct vp_mesh_shape;
int vp_cli_attach_mesh(struct vp_context *ctx, const char *cmd, const char *file,
                       const char *recorded, const char *const *shape_files, int nfiles,
                       struct vp_particles *p, struct vp_mesh_shape **meshes);
/* The summary lines of a mesh container (pieces, how its inside was
 * decided and mended, the volume estimate), and the warning line on
 * stderr when its volume and the estimate differ by more than 5 %. */
struct vp_container_info;
void vp_cli_print_mesh_container(FILE *f, const struct vp_container_info *ci);
void vp_cli_warn_container(const struct vp_container_info *ci);
/* Writes s as a JSON string literal. */
void vp_cli_json_string(FILE *f, const char *s);
#endif
