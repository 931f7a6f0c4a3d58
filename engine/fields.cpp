#include "engine/fields.hpp"

namespace furrow {

const std::vector<FieldInfo>& field_registry() {
  static const std::vector<FieldInfo> fields = {
      {"velocity", "m/s", "Velocity", true, false, false},
      {"pressure", "Pa", "Pressure", false, false, false},
      {"strain_rate", "1/s", "Equivalent plastic shear rate", false, true, false},
      {"plastic_strain", "-", "Equivalent plastic shear strain", false, false, false},
      {"packing_fraction", "-", "Packing fraction", false, false, false},
      {"phi_d", "-", "Dense packing fraction state", false, false, true},
      {"density", "kg/m^3", "Bulk density", false, false, false},
  };
  return fields;
}

const FieldInfo* find_field(const std::string& name) {
  for (const auto& f : field_registry())
    if (f.name == name) return &f;
  return nullptr;
}

}  // namespace furrow
