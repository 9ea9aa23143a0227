// Model layer (terrain, tire, granular fields, suction): later issues.
namespace scree::detail { int modelLayerVersion() { return 0; } }
