// The paper's 2-level Hough space (3.3.1): a top grid of pointers to 16^3-cell chunks that are
// allocated on first write and freed when they become empty. The top grid itself is allocated
// by slabs of one chunk layer in d as they are first written, so a space reaching far in d
// (a building-scale max_distance) costs memory only where planes are.
#pragma once

#include <cstddef>
#include <cstdint>
#include <limits>
#include <memory>
#include <vector>

namespace hough_plane_detector
{

class SparseHoughSpace
{
public:
  static constexpr int kChunkBits = 4;
  static constexpr int kChunkEdge = 1 << kChunkBits;
  static constexpr int kChunkCells = kChunkEdge * kChunkEdge * kChunkEdge;

  // Freed chunks up to max_pooled_chunks are kept for reuse: memory handed back to the system
  // and asked for again costs a page fault per 4 KB, on every frame for a per-frame space.
  static constexpr size_t kDefaultPooledChunks = 256;
  SparseHoughSpace(int size_x, int size_y, int size_z, size_t max_pooled_chunks = kDefaultPooledChunks);

  int sizeX() const { return size_x_; }
  int sizeY() const { return size_y_; }
  int sizeZ() const { return size_z_; }
  bool inBounds(int x, int y, int z) const
  {
    return x >= 0 && y >= 0 && z >= 0 && x < size_x_ && y < size_y_ && z < size_z_;
  }

  // Value of a cell; 0 outside the space or in an unallocated chunk.
  float value(int x, int y, int z) const
  {
    if (!inBounds(x, y, z)) return 0.0f;
    const Slab& slab = slabs_[z >> kChunkBits];
    if (!slab) return 0.0f;
    const float* chunk = slab[column(x, y)].get();
    return chunk ? chunk[cellIndex(x, y, z)] : 0.0f;
  }
  void add(int x, int y, int z, float v);

  // Adds weight * kx[i] * ky[j] * kz[k] around (x, y, z), kernels of 2 * radius + 1 taps;
  // no cell grows past max_value (the global space's permanence cap).
  void addSeparable(int x, int y, int z, int radius, const float* kx, const float* ky, const float* kz, float weight,
                    float max_value = std::numeric_limits<float>::max());

  // Subtracts `rate` from every cell below `cap` (never below 0) and frees chunks left empty.
  void thin(float rate, float cap);
  // Frees the chunks whose largest value is smallest until at most max_chunks remain; returns
  // how many were freed (a memory cap for long runs: the weakest evidence goes first).
  size_t evictWeakest(size_t max_chunks);
  // Frees every chunk (kept in a pool for reuse, which is not counted as used memory).
  void clear();

  size_t chunkCount() const { return allocated_.size(); }
  // Chunk indices run over [0, topLevelCount()).
  size_t topLevelCount() const { return static_cast<size_t>(chunks_x_) * chunks_y_ * chunks_z_; }
  // Bytes held by the top grid's allocated slabs and the chunks (the reuse pool is reported apart).
  size_t bytesUsed() const;
  size_t bytesPooled() const { return pool_.size() * sizeof(float) * kChunkCells; }
  // Bytes a dense float array of the same size would need.
  size_t denseBytes() const;

  // Calls f(x, y, z, value) for every non-zero cell.
  template <class F>
  void forEachNonZero(F f) const
  {
    for (int chunk_index : allocated_)
    {
      const float* chunk = chunkData(chunk_index);
      const int cz = chunk_index % chunks_z_, cy = (chunk_index / chunks_z_) % chunks_y_,
                cx = chunk_index / (chunks_z_ * chunks_y_);
      for (int i = 0; i < kChunkCells; ++i)
      {
        if (chunk[i] == 0.0f) continue;
        f((cx << kChunkBits) | (i >> (2 * kChunkBits)), (cy << kChunkBits) | ((i >> kChunkBits) & (kChunkEdge - 1)),
          (cz << kChunkBits) | (i & (kChunkEdge - 1)), chunk[i]);
      }
    }
  }

  // Raw chunk access for saving and loading maps.
  const std::vector<int>& allocatedChunkIndices() const { return allocated_; }
  const float* chunkData(int chunk_index) const
  {
    const Slab& slab = slabs_[chunk_index % chunks_z_];
    return slab ? slab[chunk_index / chunks_z_].get() : nullptr;
  }
  float* allocateChunk(int chunk_index);

private:
  // One chunk layer in d: a pointer per (x, y) chunk column.
  using Slab = std::unique_ptr<std::unique_ptr<float[]>[]>;
  void release(int chunk_index);
  std::unique_ptr<float[]>& slot(int chunk_index);
  int column(int x, int y) const { return (x >> kChunkBits) * chunks_y_ + (y >> kChunkBits); }
  int chunkIndex(int x, int y, int z) const { return column(x, y) * chunks_z_ + (z >> kChunkBits); }
  static int cellIndex(int x, int y, int z)
  {
    constexpr int m = kChunkEdge - 1;
    return ((x & m) << (2 * kChunkBits)) | ((y & m) << kChunkBits) | (z & m);
  }

  int size_x_, size_y_, size_z_;
  int chunks_x_, chunks_y_, chunks_z_;
  std::vector<Slab> slabs_;  // chunks_z_ of them, allocated on first write
  size_t slab_count_ = 0;
  size_t max_pooled_chunks_;
  std::vector<int> allocated_;
  std::vector<std::unique_ptr<float[]>> pool_;
};

}  // namespace hough_plane_detector
