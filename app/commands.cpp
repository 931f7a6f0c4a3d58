#include "app/commands.hpp"

namespace furrow::cli {

const std::vector<Command>& commands() {
  static const std::vector<Command> all = {
      command_run(), command_validate(), command_new(), command_templates(),
      command_sweep(), command_study(), command_render(), command_compare(), command_inspect(), command_edit(), command_demo(), command_bench(),
  };
  return all;
}

}  // namespace furrow::cli
