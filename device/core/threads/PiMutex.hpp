// A mutex with priority inheritance (PTHREAD_PRIO_INHERIT), for state that a realtime thread
// (the device thread, SCHED_FIFO) shares with normal-priority ones (scsynth's NRT thread
// starting a recording, reading the board, kfStatus). With std::mutex, a normal thread holding
// the lock and preempted by busy processes would stall the realtime thread for the scheduler's
// slice, several ms; here it runs at the waiter's priority until it unlocks. Lockable, so
// std::lock_guard and std::unique_lock work with it.
#pragma once

#include <pthread.h>

namespace kf {

class PiMutex {
 public:
  PiMutex() {
    pthread_mutexattr_t attributes;
    pthread_mutexattr_init(&attributes);
    inheritsPriority_ = pthread_mutexattr_setprotocol(&attributes, PTHREAD_PRIO_INHERIT) == 0;
    pthread_mutex_init(&mutex_, &attributes);
    pthread_mutexattr_destroy(&attributes);
  }
  ~PiMutex() { pthread_mutex_destroy(&mutex_); }
  PiMutex(const PiMutex&) = delete;
  PiMutex& operator=(const PiMutex&) = delete;

  void lock() { pthread_mutex_lock(&mutex_); }
  bool try_lock() { return pthread_mutex_trylock(&mutex_) == 0; }
  void unlock() { pthread_mutex_unlock(&mutex_); }

  // False where the system has no priority inheritance: then it is a plain mutex.
  bool inheritsPriority() const { return inheritsPriority_; }

 private:
  pthread_mutex_t mutex_;
  bool inheritsPriority_ = false;
};

}  // namespace kf
