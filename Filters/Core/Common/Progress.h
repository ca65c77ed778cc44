// SPDX-License-Identifier: BSD-3-Clause
// MeshFree core: how long computations report progress and learn that they should stop.
#ifndef meshfree_Progress_h
#define meshfree_Progress_h

#include <functional>

namespace meshfree
{
/// Called between blocks of work with the fraction done (0..1); return false to abort.
using ProgressCallback = std::function<bool(double)>;
} // namespace meshfree

#endif
