// What the audio-thread rules test counts: every call of the functions below made while the
// calling thread is marked as the audio thread running plugin code. The interposers
// (Interpose.c, InterposeNew.cpp) report each call here; the harness marks the audio thread and
// says what it is doing (a unit's calculation, a constructor, a command stage), so that a
// violation names the function, the UGen or command and the phase of the scenario.
// C, so that the libc interposers can be written in C: their prototypes then match glibc's.
#pragma once

#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

// One entry per counted function. try_lock is counted apart from lock: it never waits, but in a
// realtime server the plugin takes no lock at all on the audio thread (ARCHITECTURE.md).
// server_Print: the server's Print (InterfaceTable::fPrint), which scsynth allows from the NRT
// thread only.
// clang-format off
#define KF_RULES_CALLS(X)                                                                      \
  X(malloc) X(calloc) X(realloc) X(free) X(posix_memalign) X(aligned_alloc) X(memalign)        \
  X(operator_new) X(operator_delete)                                                           \
  X(pthread_mutex_lock) X(pthread_mutex_trylock)                                               \
  X(pthread_cond_wait) X(pthread_cond_timedwait) X(pthread_cond_clockwait)                     \
  X(pthread_cond_signal) X(pthread_cond_broadcast) X(sem_wait) X(sem_timedwait) X(sem_post)    \
  X(open) X(openat) X(read) X(write) X(close) X(fopen) X(fwrite) X(fprintf) X(printf) X(puts)  \
  X(poll) X(send) X(sendto) X(recv) X(recvfrom)                                                \
  X(nanosleep) X(clock_nanosleep) X(usleep) X(sleep) X(sched_yield)                            \
  X(server_Print)

enum KfRulesCall {
#define KF_RULES_ENUM(name) kf_call_##name,
  KF_RULES_CALLS(KF_RULES_ENUM)
#undef KF_RULES_ENUM
  kf_num_calls
};
// clang-format on

enum { kKfRulesTextChars = 160 };

// A kind of violation: one function, called in one activity of one phase, `count` times.
struct KfRulesViolation {
  enum KfRulesCall call;
  char phase[kKfRulesTextChars];
  char activity[kKfRulesTextChars];  // "calc", "ctor", "dtor", "command", "stage 3", ...
  char detail[kKfRulesTextChars];    // the unit or command
  uint64_t count;
};

// The calling thread is (1) or is no longer (0) the audio thread running plugin code.
void kf_rules_set_audio(int on);
// What the audio thread does now; both strings are copied only when a violation is recorded.
void kf_rules_set_activity(const char* activity, const char* detail);
// The scenario's phase, for every thread (a string that outlives the run).
void kf_rules_set_phase(const char* phase);
// Whether the calling thread is marked as the audio thread.
int kf_rules_is_audio(void);

// A witness: the calling thread's calls are counted apart (no violation), to show that the
// plugin's calls reach the interposers at all (the NRT stages allocate and lock, as they may).
void kf_rules_set_witness(int on);
uint64_t kf_rules_witnessed(enum KfRulesCall call);

// Called by every interposer: counts the call if the calling thread is marked.
void kf_rules_note(enum KfRulesCall call);

const char* kf_rules_name(enum KfRulesCall call);
uint64_t kf_rules_count(enum KfRulesCall call);
// The violations recorded (read once the audio thread has stopped); returns how many there are.
int kf_rules_violations(struct KfRulesViolation* out, int capacity);

#ifdef __cplusplus
}
#endif
