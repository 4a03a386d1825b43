// SPDX-License-Identifier: MIT
#include "tgraph/replay/thread_binding.hpp"

#include "sync.hpp"

namespace tgraph::replay {

struct BindingScope::Saved {
  detail::SavedBinding binding;
};

BindingScope::BindingScope() : saved_(std::make_unique<Saved>()) {
  detail::save_binding(saved_->binding);
}

BindingScope::~BindingScope() { detail::restore_binding(saved_->binding); }

bool BindingScope::pin(unsigned p) { return detail::pin_current_thread(p); }

unsigned hardware_pus() { return detail::hardware_pus(); }

}  // namespace tgraph::replay
