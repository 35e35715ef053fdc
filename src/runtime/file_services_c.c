/* File-system services for output that must survive a kill or a full disk (series.h5, its parts,
 * doc/DESIGN.md "series.h5: immutable parts, atomic consolidation"): list a directory, copy a
 * file durably, remove a file, the bytes free on a file system and the text of an errno.
 * Called from Fortran through mod_file_services (file_services.F90) (bind(C)). */
#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/statvfs.h>
#include <unistd.h>

static int by_name(const void *a, const void *b)
{
  return strcmp(*(char *const *)a, *(char *const *)b);
}

/* The names in dir that end in suffix, sorted, separated by '\n' in buf (NUL-terminated).
 * Returns their count, -1 if buf is too short, or -errno if dir cannot be read (a missing
 * directory counts as empty). */
int fdsusp_list_directory(const char *dir, const char *suffix, char *buf, int len)
{
  DIR *d = opendir(dir);
  if (!d) return errno == ENOENT ? (buf[0] = '\0', 0) : -errno;
  size_t nsuf = strlen(suffix), count = 0, cap = 16;
  char **names = malloc(cap * sizeof *names);
  struct dirent *e;
  while (names && (e = readdir(d))) {
    size_t n = strlen(e->d_name);
    if (n < nsuf || strcmp(e->d_name + n - nsuf, suffix) != 0 || e->d_name[0] == '.') continue;
    if (count == cap) {
      char **more = realloc(names, 2 * cap * sizeof *names);
      if (!more) break;
      names = more;
      cap *= 2;
    }
    names[count++] = strdup(e->d_name);
  }
  closedir(d);
  if (!names) return -ENOMEM;
  qsort(names, count, sizeof *names, by_name);
  int used = 0, status = (int)count;
  buf[0] = '\0';
  for (size_t k = 0; k < count; ++k) {
    int n = (int)strlen(names[k]);
    if (status >= 0 && used + n + 2 <= len) {
      memcpy(buf + used, names[k], n);
      used += n;
      buf[used++] = '\n';
      buf[used] = '\0';
    } else {
      status = -1;
    }
    free(names[k]);
  }
  free(names);
  return status;
}

/* Copy src to dst (created or truncated) and flush dst to disk. Returns 0 or errno. */
int fdsusp_copy_file(const char *src, const char *dst)
{
  int in = open(src, O_RDONLY);
  if (in < 0) return errno;
  int out = open(dst, O_WRONLY | O_CREAT | O_TRUNC, 0644);
  if (out < 0) { int e = errno; close(in); return e; }
  static char block[1 << 20];
  int status = 0;
  for (;;) {
    ssize_t n = read(in, block, sizeof block);
    if (n < 0) { if (errno == EINTR) continue; status = errno; break; }
    if (n == 0) break;
    for (ssize_t done = 0; done < n;) {
      ssize_t w = write(out, block + done, (size_t)(n - done));
      if (w < 0) { if (errno == EINTR) continue; status = errno; break; }
      done += w;
    }
    if (status) break;
  }
  if (!status && fsync(out) != 0) status = errno;
  if (close(out) != 0 && !status) status = errno;
  close(in);
  return status;
}

/* Remove a file; a missing one is no error. Returns 0 or errno. */
int fdsusp_remove_file(const char *path)
{
  if (unlink(path) != 0 && errno != ENOENT) return errno;
  return 0;
}

/* Rename without the flush of fdsusp_publish_file (moving a damaged file aside). 0 or errno. */
int fdsusp_rename_file(const char *from, const char *to)
{
  return rename(from, to) != 0 ? errno : 0;
}

/* Bytes available to this user on the file system holding path, or -1. */
double fdsusp_free_bytes(const char *path)
{
  struct statvfs s;
  if (statvfs(path, &s) != 0) return -1.0;
  return (double)s.f_bavail * (double)s.f_frsize;
}

/* The text of an errno, into buf (NUL-terminated). */
void fdsusp_errno_text(int code, char *buf, int len)
{
  if (len <= 0) return;
  strncpy(buf, strerror(code), (size_t)len - 1);
  buf[len - 1] = '\0';
}
