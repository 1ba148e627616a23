// What a witness query needs of a face, kept per thread between queries: the face's surface adaptor
// (BRepAdaptor_Surface copies the face's handles and, for B-splines, builds an evaluation cache:
// made per query it was 4 % of a certified check) and its locator (made once per source under a
// mutex; the pointer is kept so later queries skip the lock).
#pragma once

#include "brep_internal.h"

#include <BRepAdaptor_Surface.hxx>

#include <cstdint>

namespace cadclash::detail {

// A number no other BrepSource::Impl of this process has had: cached entries of a source that is
// gone can never be taken for a new one's.
std::uint64_t next_source_id();

// The calling thread's adaptor of face `local_index` of `source` (part-local, the face's location
// applied, no restriction to its domain). Valid until this thread asks for a face its cache does not
// hold yet (the cache may then let go of entries). The adaptor is the thread's own: its evaluations need no
// lock (a B-spline adaptor's evaluation cache is mutable state). Reading the
// face's surface is safe while another thread meshes the part (meshing adds triangulations and
// polygons, it never replaces a face's surface).
const BRepAdaptor_Surface& face_surface(const BrepSource::Impl& source, std::uint32_t local_index);

// source.locator(local_index), without the source's locator mutex after this thread's first call.
const FaceLocator& face_locator(const BrepSource::Impl& source, std::uint32_t local_index);

}  // namespace cadclash::detail
