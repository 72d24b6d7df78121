#pragma once
/// The controllers `--controller SPEC` can name (controller/controller_registry.h): every kind
/// registers here, once, before the command line looks one up, as the plants register before
/// `--plant` is read (RegisterRelbotPlant).

namespace hiltwin::app {

/// Registers every controller and controller kind hiltwin is built with; idempotent.
void RegisterControllers();

}  // namespace hiltwin::app
