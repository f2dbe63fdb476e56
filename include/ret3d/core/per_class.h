// One value per detected class, for options that differ by class (tracker gates, relation IoU thresholds). In YAML a
// map by class name, {Car: .., Pedestrian: .., Cyclist: ..} (YamlReader::getPerClass).
#pragma once

#include <cstddef>
#include <stdexcept>

#include "ret3d/core/types.h"

namespace ret3d {

template <typename T>
struct PerClass {
  T car{}, pedestrian{}, cyclist{};

  // Throws std::invalid_argument for ObjectClass::Unknown (no per-class value).
  const T& at(ObjectClass c) const {
    switch (c) {
      case ObjectClass::Car: return car;
      case ObjectClass::Pedestrian: return pedestrian;
      case ObjectClass::Cyclist: return cyclist;
      default: throw std::invalid_argument("PerClass: the Unknown class has no per-class value");
    }
  }
  T& at(ObjectClass c) { return const_cast<T&>(static_cast<const PerClass&>(*this).at(c)); }
  // By index k in kDetectedClasses (label - 1): the order of the relation networks' class channels.
  const T& operator[](std::size_t k) const { return at(kDetectedClasses.at(k)); }
  T& operator[](std::size_t k) { return at(kDetectedClasses.at(k)); }
};

}  // namespace ret3d
