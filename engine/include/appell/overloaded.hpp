// The overload-set visitor for std::visit:
//   std::visit(Overloaded{[](const Sphere&) {…}, [](const Disk&) {…}, …}, shape)
// Give one lambda per alternative and no `const auto&` catch-all: then adding
// an alternative to the variant makes the compiler name every visit that
// does not handle it.
#pragma once

namespace appell {

template <class... Ts>
struct Overloaded : Ts... {
  using Ts::operator()...;
};
template <class... Ts>
Overloaded(Ts...) -> Overloaded<Ts...>;

}  // namespace appell
