#pragma once
// A twin board and an ECS board joined by encoder lines, each behind its own emulated SPI bus
// and driver, on one virtual timeline: what a test of the whole path through both boards needs.

#include "hiltwin/io/emulated_fpga.h"
#include "hiltwin/io/icoboard.h"

namespace hiltwin::io {

struct BoardPair {
  BoardPair() noexcept { ecs_board.SetEncoderSource(&lines); }
  EmulatedFpga twin_board{Image::kIcoboardInverse};
  EmulatedFpga ecs_board{Image::kIcoboard};
  EmulatorToReaderLink lines{twin_board};
  EmulatedSpiBus twin_bus{twin_board};
  EmulatedSpiBus ecs_bus{ecs_board};
  IcoBoardInverse twin{twin_bus};
  IcoBoard ecs{ecs_bus};
};

}  // namespace hiltwin::io
