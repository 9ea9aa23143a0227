// Model layer (AGX agxModel chapter): terrain, TwoBodyTireModel, granular field post-processing and the
// suction gripper arrive with their issues; they attach through the step's listener hooks and public edit APIs
// of the layers below (DESIGN.md §6).
#pragma once

namespace scree::detail {
/// Version of the model layer's interface (0 until the first model lands).
int modelLayerVersion();
}  // namespace scree::detail
