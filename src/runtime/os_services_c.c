/* Operating-system services fdsusp needs and Fortran lacks: catching the signals batch
 * schedulers send before they kill a job, publishing a file atomically, and locking the output
 * directory against a second run.
 * Called from Fortran through mod_os_services (os_services.F90) (bind(C)). */
#include <errno.h>
#include <fcntl.h>
#include <signal.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>
#include <libgen.h>
#include <stdlib.h>
#include <sys/types.h>
#include <dirent.h>

static volatile sig_atomic_t stop_signal = 0;

static void on_stop_signal(int sig) { stop_signal = sig; }

/* SIGTERM and SIGUSR1 only set a flag; the time loop polls it at the end of each step, writes a
 * checkpoint and exits cleanly. Installed after PetscInitialize so it replaces PETSc's handler. */
void fdsusp_install_signal_handlers(void)
{
  struct sigaction sa;
  memset(&sa, 0, sizeof(sa));
  sa.sa_handler = on_stop_signal;
  sigemptyset(&sa.sa_mask);
  sa.sa_flags = SA_RESTART;
  sigaction(SIGTERM, &sa, NULL);
  sigaction(SIGUSR1, &sa, NULL);
}

int fdsusp_stop_signal(void) { return (int)stop_signal; }

/* fsync a file, rename it over the target, then fsync the directory, so that after a crash
 * either the old or the new file is there, complete. Returns 0 or errno. */
int fdsusp_publish_file(const char *tmp, const char *final)
{
  int fd = open(tmp, O_RDONLY);
  if (fd < 0) return errno;
  if (fsync(fd) != 0) { int e = errno; close(fd); return e; }
  close(fd);
  if (rename(tmp, final) != 0) return errno;
  char *copy = strdup(final);
  if (copy) {
    int dfd = open(dirname(copy), O_RDONLY);
    if (dfd >= 0) { fsync(dfd); close(dfd); }
    free(copy);
  }
  return 0;
}

/* What this process created for the output directory, so that a run refused before it wrote
 * anything there leaves nothing behind (fdsusp_release_directory): the directory itself and the
 * topmost of its parents that did not exist before (created_top, "" when the directory existed),
 * and whether the lock file is new (created_lock). */
static char created_dir[4096] = "";
static char created_top[4096] = "";
static int created_lock = 0;

/* Create a directory (and its parents) if missing; 0 on success or errno. */
int fdsusp_make_directory(const char *path)
{
  char buf[4096];
  size_t n = strlen(path);
  if (n == 0 || n >= sizeof(buf)) return ENAMETOOLONG;
  strcpy(buf, path);
  for (char *p = buf + 1; *p; ++p) {
    if (*p == '/') {
      *p = '\0';
      if (mkdir(buf, 0775) == 0) {
        if (created_top[0] == '\0') strcpy(created_top, buf);
      } else if (errno != EEXIST) {
        return errno;
      }
      *p = '/';
    }
  }
  if (mkdir(buf, 0775) == 0) {
    if (created_top[0] == '\0') strcpy(created_top, buf);
  } else if (errno != EEXIST) {
    return errno;
  }
  if (created_top[0] != '\0') strcpy(created_dir, buf);
  return 0;
}

/* 1 if the directory holds nothing but the lock file, else 0. */
static int holds_only_lock(const char *dir)
{
  DIR *d = opendir(dir);
  struct dirent *e;
  int only = 1;
  if (!d) return 0;
  while ((e = readdir(d)) != NULL) {
    if (strcmp(e->d_name, ".") == 0 || strcmp(e->d_name, "..") == 0 || strcmp(e->d_name, ".fdsusp.lock") == 0)
      continue;
    only = 0;
    break;
  }
  closedir(d);
  return only;
}

/* 0 if the directory can be written (a probe file is created and removed), else errno. */
int fdsusp_probe_directory(const char *path)
{
  char buf[4200];
  snprintf(buf, sizeof(buf), "%s/.fdsusp_write_probe_%d", path, (int)getpid());
  int fd = open(buf, O_WRONLY | O_CREAT | O_TRUNC, 0644);
  if (fd < 0) return errno;
  close(fd);
  unlink(buf);
  return 0;
}

/* The output directory's lock: an exclusive POSIX record lock (fcntl F_SETLK, whole file) on
 * DIR/.fdsusp.lock, taken by rank 0 at the start of a run and held by its process until it ends.
 * The kernel drops the lock when the process ends, however it ends (exit, crash, SIGKILL), so a
 * lock file left behind is not a lock: the next run takes it. That is how staleness is
 * recognised; the file's text ("pid PID on host HOST") only names the holder in messages. On NFS
 * the lock lives on the server (NLM, or NFSv4 state), which frees it when the client's lease
 * expires if the node itself died (typically 90 s).
 * Returns 0: taken (the file now names this process; `previous` is what it named before, the
 * holder of a run that ended without releasing the directory, "" after a clean release);
 * -1: a live process holds it (`previous` names it); -2: the file system offers no locks (the
 * run goes on unprotected); else the errno of creating the lock file. */
static int lock_fd = -1;
static char lock_dir[4096] = "";

static void read_holder(int fd, char *text, int len)
{
  ssize_t n = pread(fd, text, (size_t)(len - 1), 0);
  if (n < 0) n = 0;
  text[n] = '\0';
  for (ssize_t k = n - 1; k >= 0 && (text[k] == '\n' || text[k] == ' '); --k) text[k] = '\0';
}

int fdsusp_lock_directory(const char *dir, char *previous, int len)
{
  char path[4200], host[256], me[400];
  struct flock fl;
  int fd, e;
  previous[0] = '\0';
  if (lock_fd >= 0) return 0;
  snprintf(path, sizeof(path), "%s/.fdsusp.lock", dir);
  fd = open(path, O_RDWR | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
  if (fd >= 0) {
    created_lock = 1;
  } else if (errno == EEXIST) {
    fd = open(path, O_RDWR | O_CREAT | O_CLOEXEC, 0644);
  }
  if (fd < 0) return errno;
  memset(&fl, 0, sizeof(fl));
  fl.l_type = F_WRLCK;
  fl.l_whence = SEEK_SET;
  fl.l_start = 0;
  fl.l_len = 0;                                /* the whole file */
  if (fcntl(fd, F_SETLK, &fl) != 0) {
    e = errno;
    created_lock = 0;                          /* not ours to remove */
    if (e == EACCES || e == EAGAIN) {
      read_holder(fd, previous, len);
      e = -1;
    } else if (e == ENOLCK || e == EOPNOTSUPP || e == ENOSYS || e == EINVAL) {
      e = -2;
    }
    close(fd);
    return e;
  }
  read_holder(fd, previous, len);
  if (gethostname(host, sizeof(host)) != 0) strcpy(host, "?");
  host[sizeof(host) - 1] = '\0';
  snprintf(me, sizeof(me), "pid %ld on host %s\n", (long)getpid(), host);
  if (ftruncate(fd, 0) != 0 || pwrite(fd, me, strlen(me), 0) != (ssize_t)strlen(me)) {
    e = errno;
    close(fd);
    return e;
  }
  fsync(fd);
  snprintf(lock_dir, sizeof(lock_dir), "%s", dir);
  lock_fd = fd;                                /* kept open: closing any descriptor of the file drops the lock */
  return 0;
}

/* A clean end: empty the lock file (so the next run does not report a run that ended without
 * releasing it) and drop the lock. Nothing when no lock is held.
 * A run that wrote nothing into its output directory (one refused at input checking, e.g. a bad
 * checkpoint, position file or table) leaves nothing it created: the lock file if it made it, and
 * the directory and the parents it made if they hold nothing else (removed while the lock is
 * still held, so no other run is using them; rmdir refuses a directory that is not empty). */
void fdsusp_release_directory(void)
{
  char path[4200], parent[4096];
  if (lock_fd < 0) return;
  if (created_lock && holds_only_lock(lock_dir)) {
    snprintf(path, sizeof(path), "%s/.fdsusp.lock", lock_dir);
    unlink(path);
    if (created_dir[0] != '\0' && strcmp(created_dir, lock_dir) == 0) {
      /* the directory, then each parent this process made, up to the topmost */
      snprintf(parent, sizeof(parent), "%s", created_dir);
      while (rmdir(parent) == 0 && strcmp(parent, created_top) != 0) {
        char *slash = strrchr(parent, '/');
        if (slash == NULL || slash == parent) break;
        *slash = '\0';
      }
    }
    close(lock_fd);
    lock_fd = -1;
    created_lock = 0;
    return;
  }
  if (ftruncate(lock_fd, 0) == 0) fsync(lock_fd);
  close(lock_fd);
  lock_fd = -1;
}

/* The directory of the running executable (/proc/self/exe, Linux), so that data installed beside
 * it (PREFIX/share/fdsusp) is found wherever the program lives. Returns its length, or -1 (the
 * buffer holds "" then). */
int fdsusp_executable_dir(char *buf, int len)
{
  char path[4096];
  ssize_t n = readlink("/proc/self/exe", path, sizeof(path) - 1);
  if (len <= 0) return -1;
  buf[0] = '\0';
  if (n <= 0) return -1;
  path[n] = '\0';
  char *dir = dirname(path);
  size_t m = strlen(dir);
  if ((int)m >= len) return -1;
  memcpy(buf, dir, m + 1);
  return (int)m;
}

/* The value in kB of the line KEY (e.g. "VmHWM:") of /proc/self/status, or -1 where there is no
 * /proc (not Linux). */
static long status_kb(const char *key)
{
  FILE *f = fopen("/proc/self/status", "r");
  char line[256];
  size_t n = strlen(key);
  long kb = -1;
  if (!f) return -1;
  while (fgets(line, sizeof line, f)) {
    if (strncmp(line, key, n) == 0) {
      kb = strtol(line + n, NULL, 10);
      break;
    }
  }
  fclose(f);
  return kb;
}

/* The peak resident set size of this process in kB (VmHWM: exact, where getrusage and PETSc's
 * -memory_view sample), or -1 where there is no /proc. The memory report at the end of a run
 * (doc/BENCHMARKS.md §14). */
long fdsusp_peak_resident_kb(void)
{
  return status_kb("VmHWM:");
}

/* The resident set size of this process now in kB (VmRSS), or -1 where there is no /proc: what
 * the run keeps, beside the peak of its start (doc/BENCHMARKS.md §23). */
long fdsusp_resident_kb(void)
{
  return status_kb("VmRSS:");
}
