// Optional traversal counters for profiling tools (compiled in only with SYLVA_TRAVERSAL_STATS, host only):
// per-thread tallies of what a ray visits, so a benchmark built with the flag can state the work per ray
// (BVH nodes and leaves, triangles tested, the terrain's pyramid blocks and cells, the landscape's cells,
// tile nodes and plants). Without the flag every SYLVA_COUNT compiles to nothing.
#pragma once

#include <cstdint>

namespace sylva {

#if defined(SYLVA_TRAVERSAL_STATS) && !defined(__CUDA_ARCH__)
inline thread_local uint64_t g_bvhNodeVisits = 0, g_bvhLeafVisits = 0, g_triangleTests = 0;
inline thread_local uint64_t g_terrainBlockVisits = 0, g_terrainCellTests = 0;
inline thread_local uint64_t g_landNodeVisits = 0, g_landCellVisits = 0, g_tileNodeVisits = 0;
inline thread_local uint64_t g_plantBoxTests = 0, g_plantRootReads = 0, g_plantMeshEntries = 0;
// Packets (trace_packet.h): box tests of the cell tree, cells entered, tile nodes and plant boxes tested (each a test
// of all the packet's live rays; *_lanes: the rays tested), plant roots read.
inline thread_local uint64_t g_pkLandTests = 0, g_pkLandLanes = 0, g_pkCells = 0, g_pkCellLanes = 0, g_pkTileTests = 0, g_pkTileLanes = 0;
inline thread_local uint64_t g_pkPlantTests = 0, g_pkPlantLanes = 0, g_pkRootReads = 0;
#define SYLVA_COUNT(counter) (++(counter))
#define SYLVA_COUNT_ADD(counter, n) ((counter) += (n))
#else
#define SYLVA_COUNT(counter) ((void)0)
#define SYLVA_COUNT_ADD(counter, n) ((void)0)
#endif

} // namespace sylva
