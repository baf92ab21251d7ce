// The contact events' names: one table (name, aliases, meaning) read by the
// CSV and JSON writers, the CLI's summary and the viewer's timeline. A new
// event kind is one enumerator (appell/contact_events.hpp) and one row here.
#include <appell/contact_events.hpp>

namespace appell {

std::span<const NamedValue<ContactEventKind>> contactEventKindTable() {
  static const NamedValue<ContactEventKind> table[] = {
      {ContactEventKind::Touchdown, "touchdown", {}, "an open contact's gap reached 0: it closed"},
      {ContactEventKind::Bounce, "bounce", {}, "it touched down and rebounded (restitution)"},
      {ContactEventKind::LiftOff, "lift_off", {"liftoff"}, "a closed contact's normal force reached 0: it opened"},
      {ContactEventKind::Slip, "slip", {}, "a sticking contact's friction demand reached μ: it slides"},
      {ContactEventKind::Stick, "stick", {}, "a sliding contact stopped slipping and sticking holds"},
      {ContactEventKind::Feature, "feature", {}, "a closed contact moved onto another face, edge or vertex of a terrain"},
      {ContactEventKind::TimeStepping, "timestepping", {"window"}, "the automatic scheme switched to time-stepping (a mode decision failed, events piled up or the step collapsed)"},
      {ContactEventKind::Events, "events", {}, "the time-stepping window ended: the event scheme decided the modes again"},
  };
  return table;
}

const char* toString(ContactEventKind kind) {
  for (const auto& e : contactEventKindTable())
    if (e.value == kind) return e.name;
  return "?";
}

}  // namespace appell
