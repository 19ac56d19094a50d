/* SIGINT and SIGTERM: the first one asks the library to cancel (through the
 * progress callback, so it unwinds and frees as on any error) and arms a
 * one-second watchdog; if the library has not returned by then, or a second
 * signal comes, the handler removes the partial and finished outputs of this
 * run and exits at once. Either way: no output file, exit status 128 +
 * signal (130 for SIGINT, 143 for SIGTERM). */
#include "vdbpack/vdbpack.h"

#include <signal.h>
#include <sys/stat.h>
#include <string.h>
#include <unistd.h>

#include "cli/cli.h"

#define MAX_TRACKED 4
static volatile sig_atomic_t g_signal = 0;
static volatile sig_atomic_t g_done = 0;
/* the regular files (links followed) of the outputs this run has written,
 * resolved when tracked: the handler only unlinks them */
static char g_outputs[MAX_TRACKED][4096];
static volatile sig_atomic_t g_noutputs = 0;

static void put(const char *s) {
    ssize_t r = write(2, s, strlen(s));
    (void)r;
}

static void remove_tracked(void) {
    for (int i = 0; i < g_noutputs && i < MAX_TRACKED; i++) unlink(g_outputs[i]);
}

static void finish_now(void) {
    vp_remove_partial_outputs();
    remove_tracked();
    put(g_signal == SIGTERM ? "vdbpack: terminated (SIGTERM); no output written\n"
                            : "vdbpack: interrupted (SIGINT); no output written\n");
    _exit(128 + (int)g_signal);
}

static void on_alarm(int sig) {
    (void)sig;
    if (!g_done) finish_now();
}

static void on_signal(int sig) {
    if (g_done) _exit(0); /* everything is written: nothing to undo */
    if (g_signal) finish_now();
    g_signal = sig;
    alarm(1);
}

void vp_cli_signals_install(void) {
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sigemptyset(&sa.sa_mask);
    sa.sa_flags = SA_RESTART;
    sa.sa_handler = on_signal;
    sigaction(SIGINT, &sa, NULL);
    sigaction(SIGTERM, &sa, NULL);
    sa.sa_handler = on_alarm;
    sigaction(SIGALRM, &sa, NULL);
    /* past the file-size limit (ulimit -f) a write should fail with EFBIG,
     * which the writers report and clean up, not kill the process */
    signal(SIGXFSZ, SIG_IGN);
    /* a pipe whose reader has gone (-o /dev/stdout | head): the write
     * fails with EPIPE, which is reported, and the temporary file removed */
    signal(SIGPIPE, SIG_IGN);
}

int vp_cli_interrupted(void) { return (int)g_signal; }

void vp_cli_signals_track_output(const char *path) {
    /* only a regular file this run wrote is removed, the file a symbolic
     * link names rather than the link: never a device or FIFO written
     * through (-o /dev/null) */
    if (g_noutputs >= MAX_TRACKED) return;
    char file[sizeof g_outputs[0]];
    if (!vp_output_file(path, file, sizeof file)) return;
    for (int i = 0; i < g_noutputs; i++)
        if (!strcmp(g_outputs[i], file)) return;
    memcpy(g_outputs[g_noutputs], file, sizeof file);
    g_noutputs = g_noutputs + 1; /* published once its name is complete */
}

void vp_cli_signals_done(void) {
    g_done = 1;
    alarm(0);
}

int vp_cli_interrupted_exit(void) {
    alarm(0);
    remove_tracked();
    put(g_signal == SIGTERM ? "vdbpack: terminated (SIGTERM); no output written\n"
                            : "vdbpack: interrupted (SIGINT); no output written\n");
    return 128 + (int)g_signal;
}

int vp_cli_finish_output(struct vp_context *ctx, int failed, const char *out) {
    if (failed)
        return vp_cli_interrupted() ? vp_cli_interrupted_exit()
                                    : vp_cli_die(1, "%s", vp_context_message(ctx));
    if (vp_cli_interrupted()) {
        vp_cli_signals_track_output(out);
        return vp_cli_interrupted_exit();
    }
    vp_cli_signals_done();
    return 0;
}
