#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "hough_plane_detector/core/sparse_hough_space.h"

using hough_plane_detector::SparseHoughSpace;

TEST(SparseHoughSpace, AllocatesChunksOnFirstWriteOnly)
{
  SparseHoughSpace space(530, 530, 2052);
  EXPECT_EQ(space.chunkCount(), 0u);
  EXPECT_EQ(space.value(10, 20, 30), 0.0f);
  EXPECT_EQ(space.chunkCount(), 0u);  // reading never allocates
  space.add(10, 20, 30, 2.5f);
  space.add(11, 21, 31, 1.0f);  // same 16^3 chunk
  EXPECT_EQ(space.chunkCount(), 1u);
  space.add(16, 20, 30, 1.0f);  // next chunk along x
  EXPECT_EQ(space.chunkCount(), 2u);
  EXPECT_FLOAT_EQ(space.value(10, 20, 30), 2.5f);
  space.add(-1, 0, 0, 1.0f);  // outside: ignored
  space.add(530, 0, 0, 1.0f);
  EXPECT_EQ(space.chunkCount(), 2u);
}

TEST(SparseHoughSpace, ReportsMemoryAgainstTheDenseArray)
{
  SparseHoughSpace space(530, 530, 2052);
  const size_t empty = space.bytesUsed();
  EXPECT_EQ(space.denseBytes(), size_t(530) * 530 * 2052 * sizeof(float));
  space.add(100, 100, 100, 1.0f);
  const size_t chunk = SparseHoughSpace::kChunkCells * sizeof(float) + sizeof(int);
  const size_t slab = ((530 + 15) / 16) * ((530 + 15) / 16) * sizeof(void*);  // the top grid's layer of d
  EXPECT_EQ(space.bytesUsed() - empty, chunk + slab);
  space.add(300, 200, 100, 1.0f);  // another chunk of the same d layer: no new slab
  EXPECT_EQ(space.bytesUsed() - empty, 2 * chunk + slab);
  // The empty top grid is far below 0.01 % of the dense array.
  EXPECT_LT(static_cast<double>(empty) / space.denseBytes(), 0.0001);
}

TEST(SparseHoughSpace, SeparableAddAcrossChunkBordersMatchesTheOuterProduct)
{
  SparseHoughSpace space(64, 64, 64);
  const float kx[5] = {0.1f, 0.5f, 1.0f, 0.5f, 0.1f}, ky[5] = {0.2f, 0.6f, 1.0f, 0.6f, 0.2f},
              kz[5] = {0.3f, 0.7f, 1.0f, 0.7f, 0.3f};
  space.addSeparable(15, 16, 14, 2, kx, ky, kz, 2.0f);  // straddles chunk borders on every axis
  EXPECT_EQ(space.chunkCount(), 8u);
  for (int i = -2; i <= 2; ++i)
    for (int j = -2; j <= 2; ++j)
      for (int k = -2; k <= 2; ++k)
        EXPECT_FLOAT_EQ(space.value(15 + i, 16 + j, 14 + k), 2.0f * kx[i + 2] * ky[j + 2] * kz[k + 2]);
  EXPECT_EQ(space.value(15, 16, 17), 0.0f);
  // Clipped at the space's edge without touching memory outside it.
  space.addSeparable(0, 0, 63, 2, kx, ky, kz, 1.0f);
  EXPECT_FLOAT_EQ(space.value(0, 0, 63), 1.0f);
  // max_value caps every cell.
  space.addSeparable(40, 40, 40, 2, kx, ky, kz, 10.0f, 3.0f);
  EXPECT_FLOAT_EQ(space.value(40, 40, 40), 3.0f);
  EXPECT_FLOAT_EQ(space.value(41, 40, 40), 3.0f);
  EXPECT_FLOAT_EQ(space.value(42, 42, 42), 10.0f * 0.1f * 0.2f * 0.3f);
}

TEST(SparseHoughSpace, ThinningDecaysFreesEmptyChunksAndKeepsPermanentCells)
{
  SparseHoughSpace space(64, 64, 64);
  space.add(1, 1, 1, 0.25f);  // chunk A: fades
  space.add(40, 40, 40, 5.0f);  // chunk B: permanent (at the cap)
  space.add(41, 40, 40, 0.5f);  // chunk B: fades
  ASSERT_EQ(space.chunkCount(), 2u);
  space.thin(0.1f, 5.0f);
  EXPECT_NEAR(space.value(1, 1, 1), 0.15f, 1e-6);
  space.thin(0.1f, 5.0f);
  space.thin(0.1f, 5.0f);
  EXPECT_EQ(space.value(1, 1, 1), 0.0f);
  EXPECT_EQ(space.chunkCount(), 1u);  // chunk A freed
  for (int i = 0; i < 100; ++i) space.thin(0.1f, 5.0f);
  EXPECT_FLOAT_EQ(space.value(40, 40, 40), 5.0f);
  EXPECT_EQ(space.value(41, 40, 40), 0.0f);
  EXPECT_EQ(space.chunkCount(), 1u);
  int nonzero = 0;
  space.forEachNonZero([&](int x, int y, int z, float v) {
    ++nonzero;
    EXPECT_EQ(x, 40);
    EXPECT_EQ(y, 40);
    EXPECT_EQ(z, 40);
    EXPECT_FLOAT_EQ(v, 5.0f);
  });
  EXPECT_EQ(nonzero, 1);
  space.clear();
  EXPECT_EQ(space.chunkCount(), 0u);
  EXPECT_EQ(space.value(40, 40, 40), 0.0f);
}

TEST(SparseHoughSpace, EvictingKeepsTheStrongestChunks)
{
  SparseHoughSpace space(64, 64, 64);
  space.add(1, 1, 1, 0.5f);     // chunk (0,0,0): weakest
  space.add(20, 1, 1, 3.0f);    // chunk (1,0,0)
  space.add(40, 1, 1, 1.0f);    // chunk (2,0,0)
  space.add(1, 20, 1, 9.0f);    // chunk (0,1,0): strongest
  ASSERT_EQ(space.chunkCount(), 4u);
  EXPECT_EQ(space.evictWeakest(4), 0u);
  EXPECT_EQ(space.evictWeakest(2), 2u);
  EXPECT_EQ(space.chunkCount(), 2u);
  EXPECT_EQ(space.value(1, 1, 1), 0.0f);
  EXPECT_EQ(space.value(40, 1, 1), 0.0f);
  EXPECT_FLOAT_EQ(space.value(20, 1, 1), 3.0f);
  EXPECT_FLOAT_EQ(space.value(1, 20, 1), 9.0f);
}

TEST(SparseHoughSpace, FreedChunksArePooledUpToTheSpacesLimit)
{
  // Three chunks written and cleared: a pool of two keeps two for reuse, the third goes back.
  SparseHoughSpace space(64, 64, 64, 2);
  for (int z : {0, 16, 32}) space.add(0, 0, z, 1.0f);
  ASSERT_EQ(space.chunkCount(), 3u);
  space.clear();
  EXPECT_EQ(space.chunkCount(), 0u);
  EXPECT_EQ(space.bytesPooled(), 2u * sizeof(float) * SparseHoughSpace::kChunkCells);
  // A reused chunk starts at zero.
  space.add(0, 0, 48, 2.0f);
  EXPECT_EQ(space.bytesPooled(), 1u * sizeof(float) * SparseHoughSpace::kChunkCells);
  EXPECT_EQ(space.value(0, 0, 48), 2.0f);
  EXPECT_EQ(space.value(0, 0, 49), 0.0f);
  EXPECT_EQ(space.value(0, 0, 0), 0.0f);
  SparseHoughSpace default_pool(64, 64, 64);
  for (int z : {0, 16, 32}) default_pool.add(0, 0, z, 1.0f);
  default_pool.clear();
  EXPECT_EQ(default_pool.bytesPooled(), 3u * sizeof(float) * SparseHoughSpace::kChunkCells);
}
