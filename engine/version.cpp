// Keeps furrow_engine non-empty while modules land; reports the build version.
namespace furrow {
const char* version() { return FURROW_VERSION; }
}  // namespace furrow
