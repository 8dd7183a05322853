// Measures of a deformation result, for the experiments, the benchmarks and the tests. Each
// compares the deformed positions of a mesh (n x 3, the same connectivity) with its rest shape.
//  - cross_section_ratios(): the rings of a bar-like mesh, the vertices sharing one rest
//    coordinate along `axis` (equal to 1e-9 of the bounding-box diagonal; rings of fewer than 8
//    vertices, the caps' interiors, are skipped), each ring's mean distance to its centroid
//    after over before, in the order of the coordinate. 1: the cross-section keeps its size; the
//    linear energy's twisted bars fall to 0.25-0.4 (the candy wrapper).
//  - inverted_faces(): faces that agreed with their edge neighbours before the deformation (the
//    normal within 60 degrees of their area-weighted mean normal) and point against it after:
//    local fold-overs. Faces on sharp features (nearly perpendicular to their neighbours) are
//    left out, where a harmless wobble would flip the sign. A rigid motion or a smooth bend has
//    none.
//  - point_distances(): the RMS and the largest distance between corresponding vertices.
#pragma once

#include <vector>

#include "specdeform/mesh/triangle_mesh.h"

namespace specdeform {

std::vector<double> cross_section_ratios(const Vertices& rest, const Vertices& deformed, int axis);

int inverted_faces(const TriangleMesh& rest, const Vertices& deformed);

struct PointDistances {
  double rms = 0.0;
  double max = 0.0;
};
PointDistances point_distances(const Vertices& a, const Vertices& b);

}  // namespace specdeform
