// Model layer (terrain, tire, granular fields, suction): later issues.
#include "scree/model/model.h"

namespace scree::detail {
int modelLayerVersion() { return 0; }
}  // namespace scree::detail
