// limit_mesher_threads, hold_mesher_threads: OCCT's parallel loops on a pool of a given size, or on
// every core (tessellate.h).
#include "cadclash/tessellate.h"

#include <OSD_Parallel.hxx>
#include <OSD_ThreadPool.hxx>

#include <cassert>

namespace cadclash {

int limit_mesher_threads(int threads) {
  assert(threads >= 0);
  if (threads == 0) {
    // Back to OCCT's default: TBB's scheduler, every core (the pool, if made, stays idle).
    OSD_Parallel::SetUseOcctThreads(Standard_False);
    return OSD_Parallel::NbLogicalProcessors();
  }
  // OSD_Parallel hands its loops to TBB unless told to use OCCT's own pool; TBB would take every
  // core. The default pool takes its size when first made, and Init resizes one made already.
  OSD_Parallel::SetUseOcctThreads(Standard_True);
  const Handle(OSD_ThreadPool)& pool = OSD_ThreadPool::DefaultPool(threads);
  if (pool->NbThreads() != threads) pool->Init(threads);
  pool->SetNbDefaultThreadsToLaunch(threads);
  return pool->NbThreads();
}

int hold_mesher_threads(int threads) {
  assert(threads >= 0);
  return limit_mesher_threads(threads < OSD_Parallel::NbLogicalProcessors() ? threads : 0);
}

}  // namespace cadclash
