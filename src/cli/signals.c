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
static const char *volatile g_outputs[MAX_TRACKED];

static void put(const char *s) {
    ssize_t r = write(2, s, strlen(s));
    (void)r;
}

static void finish_now(void) {
    vp_remove_partial_outputs();
    for (int i = 0; i < MAX_TRACKED; i++)
        if (g_outputs[i]) unlink(g_outputs[i]);
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
}

int vp_cli_interrupted(void) { return (int)g_signal; }

void vp_cli_signals_track_output(const char *path) {
    /* only a regular file this run made is removed: never a device or
     * FIFO written through (-o /dev/null), nor a symbolic link */
    struct stat st;
    if (lstat(path, &st) != 0 || !S_ISREG(st.st_mode)) return;
    for (int i = 0; i < MAX_TRACKED; i++)
        if (!g_outputs[i]) {
            g_outputs[i] = path;
            return;
        }
}

void vp_cli_signals_done(void) {
    g_done = 1;
    alarm(0);
}

int vp_cli_interrupted_exit(void) {
    alarm(0);
    for (int i = 0; i < MAX_TRACKED; i++)
        if (g_outputs[i]) unlink(g_outputs[i]);
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
