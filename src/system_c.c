/* Operating-system services fdsusp needs and Fortran lacks: catching the signals batch
 * schedulers send before they kill a job, and publishing a file atomically.
 * Called from Fortran through mod_system (system.F90) (bind(C)). */
#include <errno.h>
#include <fcntl.h>
#include <signal.h>
#include <stdio.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>
#include <libgen.h>
#include <stdlib.h>

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
