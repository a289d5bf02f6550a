// The server's real-time memory (RTAlloc, RTFree), as scsynth's pool: one block reserved up
// front and carved on the audio thread without ever calling malloc. Blocks come in powers of two,
// each size with a free list; a new block is cut from the end of what was never used. Like
// scsynth's pool it is for one thread, the audio thread; a request beyond it fails (nullptr), as
// a server with too small a memSize does.
#pragma once

#include <cstddef>
#include <cstring>
#include <memory>

namespace kf::rules {

class RtPool {
 public:
  explicit RtPool(std::size_t bytes) : storage_(new unsigned char[bytes]), capacity_(bytes) {}

  void* allocate(std::size_t size) {
    const int sizeClass = classOf(size);
    if (sizeClass > kMaxClass) return nullptr;
    Block* block = free_[sizeClass];
    if (block != nullptr) {
      free_[sizeClass] = block->next;
    } else {
      const std::size_t bytes = std::size_t{1} << sizeClass;
      if (used_ + bytes > capacity_) return nullptr;
      block = reinterpret_cast<Block*>(storage_.get() + used_);
      used_ += bytes;
    }
    block->sizeClass = sizeClass;
    return reinterpret_cast<unsigned char*>(block) + kHeader;
  }

  void release(void* pointer) {
    if (pointer == nullptr) return;
    Block* block = blockOf(pointer);
    block->next = free_[block->sizeClass];
    free_[block->sizeClass] = block;
  }

  void* reallocate(void* pointer, std::size_t size) {
    if (pointer == nullptr) return allocate(size);
    const std::size_t room = (std::size_t{1} << blockOf(pointer)->sizeClass) - kHeader;
    if (size <= room) return pointer;
    void* moved = allocate(size);
    if (moved == nullptr) return nullptr;
    std::memcpy(moved, pointer, room);
    release(pointer);
    return moved;
  }

 private:
  // Before every block: its size class, and the next free block while it is free. 16 bytes, so
  // that what the plugin gets is aligned as malloc's.
  struct alignas(16) Block {
    Block* next;
    int sizeClass;
  };
  static constexpr std::size_t kHeader = sizeof(Block);
  static constexpr int kMinClass = 5;   // 32 bytes
  static constexpr int kMaxClass = 40;  // any request the block could hold fits a class

  static int classOf(std::size_t size) {
    int sizeClass = kMinClass;
    while (sizeClass <= kMaxClass && (std::size_t{1} << sizeClass) < size + kHeader) ++sizeClass;
    return sizeClass;
  }
  static Block* blockOf(void* pointer) {
    return reinterpret_cast<Block*>(static_cast<unsigned char*>(pointer) - kHeader);
  }

  std::unique_ptr<unsigned char[]> storage_;
  std::size_t capacity_;
  std::size_t used_ = 0;
  Block* free_[kMaxClass + 1] = {};
};

}  // namespace kf::rules
