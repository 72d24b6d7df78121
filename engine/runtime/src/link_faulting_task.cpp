#include "hiltwin/runtime/link_faulting_task.h"

namespace hiltwin::runtime {

io::ExchangeStatus LinkFaultingTask::Exchange(bool live_outputs) noexcept {
  schedule_.Arm(exchanges_++, board_.faults());
  return wrapped().Exchange(live_outputs);
}

}  // namespace hiltwin::runtime
