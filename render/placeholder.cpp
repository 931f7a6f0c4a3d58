namespace furrow::render {
int placeholder() { return 0; }
}  // namespace furrow::render
