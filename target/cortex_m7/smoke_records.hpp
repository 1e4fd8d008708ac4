#pragma once
// What the smoke image (smoke_main.cpp) and its host-side tests (tests/target) agree on: the record
// type that ends each echo round, and the image's exit statuses. Constants only, so the host's tests
// include it too.
#include <cstdint>

namespace exc::target::smoke {

// Ends a round's batch from the host; the image echoes it last, after the round's other records.
inline constexpr std::uint8_t kEchoEndRecord = 0xFE;

// Exit statuses besides 0 (every round echoed) and start_up.hpp's kFaultExitStatus.
inline constexpr int kBadArguments = 2;   // the console names the argument
inline constexpr int kLinkFailed = 3;     // the console names the link's status
inline constexpr int kEarlyExit = 4;      // --exit-after-records: stopped on purpose, mid-round
inline constexpr int kSelfCheckFailed = 5;  // a check the image makes of itself failed (the console says which)

}  // namespace exc::target::smoke
