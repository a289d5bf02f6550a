// The libc functions the audio thread must not call, defined in the test executable: it is
// linked with its symbols exported (ENABLE_EXPORTS), so the plugin it dlopens, libstdc++ and
// libc itself resolve these names to the definitions here. Each one reports the call
// (Counting.h) and forwards to glibc's own.
//
// The allocator forwards to glibc's __libc_* entry points, not through dlsym: dlsym itself
// allocates (calloc), and its answer is not needed for them. The others are looked up once with
// dlsym(RTLD_NEXT) before main (lookUpAll), so that the audio thread never runs dlsym.
#define _GNU_SOURCE
#include <dlfcn.h>
#include <errno.h>
#include <fcntl.h>
#include <poll.h>
#include <pthread.h>
#include <sched.h>
#include <semaphore.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <sys/socket.h>
#include <time.h>
#include <unistd.h>

#include "Counting.h"

extern void* __libc_malloc(size_t size);
extern void* __libc_calloc(size_t count, size_t size);
extern void* __libc_realloc(void* pointer, size_t size);
extern void __libc_free(void* pointer);
extern void* __libc_memalign(size_t alignment, size_t size);

// --- allocation ----------------------------------------------------------------------------

void* malloc(size_t size) {
  kf_rules_note(kf_call_malloc);
  return __libc_malloc(size);
}

void* calloc(size_t count, size_t size) {
  kf_rules_note(kf_call_calloc);
  return __libc_calloc(count, size);
}

void* realloc(void* pointer, size_t size) {
  kf_rules_note(kf_call_realloc);
  return __libc_realloc(pointer, size);
}

// free(NULL) does nothing, so it is no violation.
void free(void* pointer) {
  if (pointer == NULL) return;
  kf_rules_note(kf_call_free);
  __libc_free(pointer);
}

int posix_memalign(void** out, size_t alignment, size_t size) {
  kf_rules_note(kf_call_posix_memalign);
  if (alignment == 0 || alignment % sizeof(void*) != 0 || (alignment & (alignment - 1)) != 0) return EINVAL;
  void* pointer = __libc_memalign(alignment, size);
  if (pointer == NULL) return ENOMEM;
  *out = pointer;
  return 0;
}

void* aligned_alloc(size_t alignment, size_t size) {
  kf_rules_note(kf_call_aligned_alloc);
  return __libc_memalign(alignment, size);
}

void* memalign(size_t alignment, size_t size) {
  kf_rules_note(kf_call_memalign);
  return __libc_memalign(alignment, size);
}

// --- the rest: glibc's definitions, found once ----------------------------------------------

#define KF_REAL(name) static __typeof__(&name) real_##name;
// clang-format off
#define KF_FORWARDED(X)                                                                        \
  X(pthread_mutex_lock) X(pthread_mutex_trylock)                                               \
  X(pthread_cond_wait) X(pthread_cond_timedwait) X(pthread_cond_clockwait)                     \
  X(pthread_cond_signal) X(pthread_cond_broadcast) X(sem_wait) X(sem_timedwait) X(sem_post)    \
  X(open) X(openat) X(read) X(write) X(close) X(fopen) X(fwrite) X(vfprintf) X(vprintf)        \
  X(puts) X(poll) X(send) X(sendto) X(recv) X(recvfrom)                                        \
  X(nanosleep) X(clock_nanosleep) X(usleep) X(sleep) X(sched_yield)
// clang-format on
KF_FORWARDED(KF_REAL)

static void* nextDefinition(const char* name) {
  void* found = dlsym(RTLD_NEXT, name);
  if (found == NULL) abort();  // a libc without it: nothing to forward to
  return found;
}

// Before main and before any thread of the test: the audio thread only ever reads the pointers.
// A call before this constructor (another constructor) looks its function up itself.
#define KF_LOOK_UP(name) real_##name = (__typeof__(&name))nextDefinition(#name);
__attribute__((constructor(101))) static void lookUpAll(void) { KF_FORWARDED(KF_LOOK_UP) }
#define REAL(name)                                                                   \
  ({                                                                                 \
    if (real_##name == NULL) real_##name = (__typeof__(&name))nextDefinition(#name); \
    real_##name;                                                                     \
  })

// --- locks, conditions, semaphores ----------------------------------------------------------

int pthread_mutex_lock(pthread_mutex_t* mutex) {
  kf_rules_note(kf_call_pthread_mutex_lock);
  return REAL(pthread_mutex_lock)(mutex);
}

int pthread_mutex_trylock(pthread_mutex_t* mutex) {
  kf_rules_note(kf_call_pthread_mutex_trylock);
  return REAL(pthread_mutex_trylock)(mutex);
}

int pthread_cond_wait(pthread_cond_t* cond, pthread_mutex_t* mutex) {
  kf_rules_note(kf_call_pthread_cond_wait);
  return REAL(pthread_cond_wait)(cond, mutex);
}

int pthread_cond_timedwait(pthread_cond_t* cond, pthread_mutex_t* mutex, const struct timespec* until) {
  kf_rules_note(kf_call_pthread_cond_timedwait);
  return REAL(pthread_cond_timedwait)(cond, mutex, until);
}

int pthread_cond_clockwait(pthread_cond_t* cond, pthread_mutex_t* mutex, clockid_t clock,
                           const struct timespec* until) {
  kf_rules_note(kf_call_pthread_cond_clockwait);
  return REAL(pthread_cond_clockwait)(cond, mutex, clock, until);
}

int pthread_cond_signal(pthread_cond_t* cond) {
  kf_rules_note(kf_call_pthread_cond_signal);
  return REAL(pthread_cond_signal)(cond);
}

int pthread_cond_broadcast(pthread_cond_t* cond) {
  kf_rules_note(kf_call_pthread_cond_broadcast);
  return REAL(pthread_cond_broadcast)(cond);
}

int sem_wait(sem_t* sem) {
  kf_rules_note(kf_call_sem_wait);
  return REAL(sem_wait)(sem);
}

int sem_timedwait(sem_t* sem, const struct timespec* until) {
  kf_rules_note(kf_call_sem_timedwait);
  return REAL(sem_timedwait)(sem, until);
}

int sem_post(sem_t* sem) {
  kf_rules_note(kf_call_sem_post);
  return REAL(sem_post)(sem);
}

// --- files, streams and sockets -------------------------------------------------------------

int open(const char* path, int flags, ...) {
  kf_rules_note(kf_call_open);
  mode_t mode = 0;
  if (flags & (O_CREAT | O_TMPFILE)) {
    va_list args;
    va_start(args, flags);
    mode = va_arg(args, mode_t);
    va_end(args);
  }
  return REAL(open)(path, flags, mode);
}

int openat(int directory, const char* path, int flags, ...) {
  kf_rules_note(kf_call_openat);
  mode_t mode = 0;
  if (flags & (O_CREAT | O_TMPFILE)) {
    va_list args;
    va_start(args, flags);
    mode = va_arg(args, mode_t);
    va_end(args);
  }
  return REAL(openat)(directory, path, flags, mode);
}

ssize_t read(int fd, void* buffer, size_t size) {
  kf_rules_note(kf_call_read);
  return REAL(read)(fd, buffer, size);
}

ssize_t write(int fd, const void* buffer, size_t size) {
  kf_rules_note(kf_call_write);
  return REAL(write)(fd, buffer, size);
}

int close(int fd) {
  kf_rules_note(kf_call_close);
  return REAL(close)(fd);
}

FILE* fopen(const char* path, const char* mode) {
  kf_rules_note(kf_call_fopen);
  return REAL(fopen)(path, mode);
}

size_t fwrite(const void* data, size_t size, size_t count, FILE* stream) {
  kf_rules_note(kf_call_fwrite);
  return REAL(fwrite)(data, size, count, stream);
}

// Inside libc, printf and friends write through internal calls, not write(): counted here.
int fprintf(FILE* stream, const char* format, ...) {
  kf_rules_note(kf_call_fprintf);
  va_list args;
  va_start(args, format);
  const int result = REAL(vfprintf)(stream, format, args);
  va_end(args);
  return result;
}

int printf(const char* format, ...) {
  kf_rules_note(kf_call_printf);
  va_list args;
  va_start(args, format);
  const int result = REAL(vprintf)(format, args);
  va_end(args);
  return result;
}

int puts(const char* text) {
  kf_rules_note(kf_call_puts);
  return REAL(puts)(text);
}

int poll(struct pollfd* fds, nfds_t count, int timeoutMs) {
  kf_rules_note(kf_call_poll);
  return REAL(poll)(fds, count, timeoutMs);
}

ssize_t send(int fd, const void* buffer, size_t size, int flags) {
  kf_rules_note(kf_call_send);
  return REAL(send)(fd, buffer, size, flags);
}

ssize_t sendto(int fd, const void* buffer, size_t size, int flags, const struct sockaddr* to, socklen_t toSize) {
  kf_rules_note(kf_call_sendto);
  return REAL(sendto)(fd, buffer, size, flags, to, toSize);
}

ssize_t recv(int fd, void* buffer, size_t size, int flags) {
  kf_rules_note(kf_call_recv);
  return REAL(recv)(fd, buffer, size, flags);
}

ssize_t recvfrom(int fd, void* buffer, size_t size, int flags, struct sockaddr* from, socklen_t* fromSize) {
  kf_rules_note(kf_call_recvfrom);
  return REAL(recvfrom)(fd, buffer, size, flags, from, fromSize);
}

// --- sleeping -------------------------------------------------------------------------------

int nanosleep(const struct timespec* duration, struct timespec* left) {
  kf_rules_note(kf_call_nanosleep);
  return REAL(nanosleep)(duration, left);
}

int clock_nanosleep(clockid_t clock, int flags, const struct timespec* until, struct timespec* left) {
  kf_rules_note(kf_call_clock_nanosleep);
  return REAL(clock_nanosleep)(clock, flags, until, left);
}

int usleep(useconds_t microseconds) {
  kf_rules_note(kf_call_usleep);
  return REAL(usleep)(microseconds);
}

unsigned int sleep(unsigned int seconds) {
  kf_rules_note(kf_call_sleep);
  return REAL(sleep)(seconds);
}

int sched_yield(void) {
  kf_rules_note(kf_call_sched_yield);
  return REAL(sched_yield)();
}
