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
      if (mkdir(buf, 0775) != 0 && errno != EEXIST) return errno;
      *p = '/';
    }
  }
  if (mkdir(buf, 0775) != 0 && errno != EEXIST) return errno;
  return 0;
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
  fd = open(path, O_RDWR | O_CREAT | O_CLOEXEC, 0644);
  if (fd < 0) return errno;
  memset(&fl, 0, sizeof(fl));
  fl.l_type = F_WRLCK;
  fl.l_whence = SEEK_SET;
  fl.l_start = 0;
  fl.l_len = 0;                                /* the whole file */
  if (fcntl(fd, F_SETLK, &fl) != 0) {
    e = errno;
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
  lock_fd = fd;                                /* kept open: closing any descriptor of the file drops the lock */
  return 0;
}

/* A clean end: empty the lock file (so the next run does not report a run that ended without
 * releasing it) and drop the lock. Nothing when no lock is held. */
void fdsusp_release_directory(void)
{
  if (lock_fd < 0) return;
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
