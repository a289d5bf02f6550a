// The counters behind Counting.h. Everything here runs inside the interposed functions, so it
// calls none of them: atomics, fixed arrays and byte copies only.
#include "Counting.h"

#include <stdatomic.h>
#include <string.h>

// Initial-exec TLS: a plain offset from the thread pointer, no __tls_get_addr (which may
// allocate) and usable from the first malloc of the process on.
static __thread int tAudio __attribute__((tls_model("initial-exec")));
static __thread int tWitness __attribute__((tls_model("initial-exec")));
static __thread const char* tActivity __attribute__((tls_model("initial-exec")));
static __thread const char* tDetail __attribute__((tls_model("initial-exec")));

static _Atomic(const char*) gPhase = "";
static _Atomic uint64_t gCounts[kf_num_calls];
static _Atomic uint64_t gWitnessed[kf_num_calls];

// Written by the audio thread only (the only marked thread), read after it stopped.
enum { kMaxViolations = 256 };
static struct KfRulesViolation gViolations[kMaxViolations];
static _Atomic int gNumViolations;

static const char* const kNames[] = {
#define KF_RULES_NAME(name) #name,
    KF_RULES_CALLS(KF_RULES_NAME)
#undef KF_RULES_NAME
};

void kf_rules_set_audio(int on) { tAudio = on; }

int kf_rules_is_audio(void) { return tAudio; }

void kf_rules_set_witness(int on) { tWitness = on; }

uint64_t kf_rules_witnessed(enum KfRulesCall call) { return atomic_load(&gWitnessed[call]); }

void kf_rules_set_activity(const char* activity, const char* detail) {
  tActivity = activity;
  tDetail = detail;
}

void kf_rules_set_phase(const char* phase) { atomic_store(&gPhase, phase); }

static void copyText(char* to, const char* from) {
  size_t n = from != NULL ? strlen(from) : 0;
  if (n >= kKfRulesTextChars) n = kKfRulesTextChars - 1;
  if (n > 0) memcpy(to, from, n);
  to[n] = '\0';
}

static int sameText(const char* recorded, const char* text) {
  return strncmp(recorded, text != NULL ? text : "", kKfRulesTextChars - 1) == 0;
}

void kf_rules_note(enum KfRulesCall call) {
  if (tWitness) atomic_fetch_add(&gWitnessed[call], 1);
  if (!tAudio) return;
  atomic_fetch_add(&gCounts[call], 1);
  const char* phase = atomic_load(&gPhase);
  const int n = atomic_load(&gNumViolations);
  for (int i = 0; i < n; ++i) {
    struct KfRulesViolation* v = &gViolations[i];
    if (v->call == call && sameText(v->phase, phase) && sameText(v->activity, tActivity) &&
        sameText(v->detail, tDetail)) {
      ++v->count;
      return;
    }
  }
  if (n == kMaxViolations) return;  // the counts still say it
  struct KfRulesViolation* v = &gViolations[n];
  v->call = call;
  copyText(v->phase, phase);
  copyText(v->activity, tActivity);
  copyText(v->detail, tDetail);
  v->count = 1;
  atomic_store(&gNumViolations, n + 1);
}

const char* kf_rules_name(enum KfRulesCall call) { return kNames[call]; }

uint64_t kf_rules_count(enum KfRulesCall call) { return atomic_load(&gCounts[call]); }

int kf_rules_violations(struct KfRulesViolation* out, int capacity) {
  const int n = atomic_load(&gNumViolations);
  for (int i = 0; i < n && i < capacity; ++i) out[i] = gViolations[i];
  return n;
}
