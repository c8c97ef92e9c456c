#include "hough_plane_detector/core/sparse_hough_space.h"

#include <algorithm>
#include <cstring>

namespace hough_plane_detector
{

SparseHoughSpace::SparseHoughSpace(int size_x, int size_y, int size_z, size_t max_pooled_chunks)
  : size_x_(size_x), size_y_(size_y), size_z_(size_z), max_pooled_chunks_(max_pooled_chunks)
{
  chunks_x_ = (size_x + kChunkEdge - 1) / kChunkEdge;
  chunks_y_ = (size_y + kChunkEdge - 1) / kChunkEdge;
  chunks_z_ = (size_z + kChunkEdge - 1) / kChunkEdge;
  slabs_.resize(chunks_z_);
}

std::unique_ptr<float[]>& SparseHoughSpace::slot(int chunk_index)
{
  Slab& slab = slabs_[chunk_index % chunks_z_];
  if (!slab)
  {
    slab.reset(new std::unique_ptr<float[]>[static_cast<size_t>(chunks_x_) * chunks_y_]);
    ++slab_count_;
  }
  return slab[chunk_index / chunks_z_];
}

float* SparseHoughSpace::allocateChunk(int chunk_index)
{
  auto& slot = this->slot(chunk_index);
  if (!slot)
  {
    if (!pool_.empty())
    {
      slot = std::move(pool_.back());
      pool_.pop_back();
    }
    else
    {
      slot.reset(new float[kChunkCells]);
    }
    std::memset(slot.get(), 0, sizeof(float) * kChunkCells);
    allocated_.push_back(chunk_index);
  }
  return slot.get();
}

void SparseHoughSpace::add(int x, int y, int z, float v)
{
  if (!inBounds(x, y, z)) return;
  allocateChunk(chunkIndex(x, y, z))[cellIndex(x, y, z)] += v;
}

void SparseHoughSpace::addSeparable(int x, int y, int z, int radius, const float* kx, const float* ky, const float* kz,
                                    float weight, float max_value)
{
  const int z_lo = std::max(0, z - radius), z_hi = std::min(size_z_ - 1, z + radius);
  if (z_lo > z_hi) return;
  for (int i = -radius; i <= radius; ++i)
  {
    const int xi = x + i;
    if (xi < 0 || xi >= size_x_) continue;
    for (int j = -radius; j <= radius; ++j)
    {
      const int yj = y + j;
      if (yj < 0 || yj >= size_y_) continue;
      const float wxy = weight * kx[i + radius] * ky[j + radius];
      // Runs along z stay inside one chunk except where they cross a chunk boundary.
      int zk = z_lo;
      while (zk <= z_hi)
      {
        const int run_end = std::min(z_hi, zk | (kChunkEdge - 1));
        float* chunk = allocateChunk(chunkIndex(xi, yj, zk));
        float* cell = chunk + cellIndex(xi, yj, zk);
        const float* kernel = kz + (zk - z + radius);
        for (int k = 0; k <= run_end - zk; ++k) cell[k] = std::min(max_value, cell[k] + wxy * kernel[k]);
        zk = run_end + 1;
      }
    }
  }
}

void SparseHoughSpace::thin(float rate, float cap)
{
  std::vector<int> kept;
  kept.reserve(allocated_.size());
  for (int chunk_index : allocated_)
  {
    float* chunk = slot(chunk_index).get();
    float any = 0.0f;
    for (int i = 0; i < kChunkCells; ++i)
    {
      const float v = chunk[i];
      const float thinned = v >= cap ? v : std::max(0.0f, v - rate);
      chunk[i] = thinned;
      any = std::max(any, thinned);
    }
    if (any > 0.0f)
      kept.push_back(chunk_index);
    else
      release(chunk_index);
  }
  allocated_.swap(kept);
}

size_t SparseHoughSpace::evictWeakest(size_t max_chunks)
{
  if (allocated_.size() <= max_chunks) return 0;
  std::vector<std::pair<float, int>> strength;
  strength.reserve(allocated_.size());
  for (int chunk_index : allocated_)
  {
    const float* chunk = chunkData(chunk_index);
    strength.emplace_back(*std::max_element(chunk, chunk + kChunkCells), chunk_index);
  }
  const size_t evicted = allocated_.size() - max_chunks;
  std::nth_element(strength.begin(), strength.begin() + evicted, strength.end());
  std::vector<int> drop;
  drop.reserve(evicted);
  for (size_t i = 0; i < evicted; ++i) drop.push_back(strength[i].second);
  std::sort(drop.begin(), drop.end());
  std::vector<int> kept;
  kept.reserve(max_chunks);
  for (int chunk_index : allocated_)
  {
    if (std::binary_search(drop.begin(), drop.end(), chunk_index))
      release(chunk_index);
    else
      kept.push_back(chunk_index);
  }
  allocated_.swap(kept);
  return evicted;
}

void SparseHoughSpace::clear()
{
  for (int chunk_index : allocated_) release(chunk_index);
  allocated_.clear();
}

void SparseHoughSpace::release(int chunk_index)
{
  // The pool spares a malloc and fresh pages per chunk; beyond it memory goes back.
  if (pool_.size() < max_pooled_chunks_)
    pool_.push_back(std::move(slot(chunk_index)));
  else
    slot(chunk_index).reset();
}

size_t SparseHoughSpace::bytesUsed() const
{
  return slabs_.size() * sizeof(Slab) + slab_count_ * static_cast<size_t>(chunks_x_) * chunks_y_ * sizeof(std::unique_ptr<float[]>) +
         allocated_.size() * (sizeof(float) * kChunkCells + sizeof(int));
}

size_t SparseHoughSpace::denseBytes() const
{
  return static_cast<size_t>(size_x_) * size_y_ * size_z_ * sizeof(float);
}

}  // namespace hough_plane_detector
