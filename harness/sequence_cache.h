// A simulated sequence kept on disk, exactly, so that several runs of one scenario simulate it
// once: a suite's runs that share a sequence (same scenario, overrides, seed and max_frames;
// configurations and strides differ) read the frames the first of them simulated.
//
// A cache entry is a marked folder of kind "sequence" (output_folder.h), written as a work
// folder and published only when every frame is in it:
//   sequence.json   format, the vobench version, the effective scenario (YAML, without its
//                   name) and max_frames it was simulated for, the calibration, the path
//                   follower's report (sim/navigation.h: a run on the entry reports what the
//                   robot did as one that simulates), and per frame
//                   the offset, size and FNV-1a hash (spec.h's Fnv1aHex) of its record
//   frames.bin      the frames' records, one after the other, in this machine's byte order:
//                   time, ground-truth flag and pose (16 doubles), the left, right and depth
//                   images (rows, cols, type, then the pixels), the IMU samples (every field)
// Everything is stored as the simulator made it (the doubles' bits, the images' bytes), so the
// frames read back are equal bit for bit to those simulated, and a run on them writes the same
// run folder as a run that simulates (the timing figures aside). The calibration's numbers are
// JSON numbers (nlohmann writes them with the digits that read back to the same double).
//
// Sharing: OpenSharedScenarioSequence(scenario, max_frames, cache_dir) takes the writer lock
// "<entry>.writer.lock" beside the entry cache_dir/<key> (key: FNV-1a of the scenario's YAML
// without its name, its scene files' hash, and max_frames), waiting while another process holds it;
// simulates the entry when it is missing or not usable (no marker, an unreadable sequence.json,
// another format, version, scenario, scene files (the MJCF and its includes, or the floor plan and
// its robot, by content) or max_frames, a frames.bin of another size: the entry is written again);
// releases the lock; and reads the frames from the entry. A record whose hash does not match (the
// file changed after it was written) fails the run with a message naming the file and frame. The
// entry is not tied to the code that simulated it beyond the version string: `git describe` does
// not see uncommitted changes, so remove a cache folder kept across builds (a suite's lives in its
// work folder and is removed when the call ends). A closed-loop scenario (navigation: vo) is never
// cached: its frames depend on the VO (`run --sequence-cache` simulates it in the loop).
#pragma once

#include <string>

#include "harness/output_folder.h"
#include "harness/pipeline.h"
#include "sim/scenario.h"
#include "sim/simulator.h"

namespace harness {

constexpr int kSequenceCacheFormat = 2;  // sequence.json's "format"

// The name of the entry of `scenario` (its name ignored) simulated for max_frames (0 = all)
// in a cache folder: 16 hex digits.
std::string SequenceCacheKey(const sim::Scenario& scenario, int max_frames);

// Simulates `scenario` (its first max_frames frames, 0 = all) into the entry folder `dir`
// (replacing an earlier entry there; nothing at dir on failure or interruption). `progress`: a
// progress display on stderr.
bool WriteSequenceCache(const sim::Scenario& scenario, int max_frames, const std::string& dir,
                        bool progress, std::string* error);

// Whether `dir` is a complete entry of `scenario` and max_frames written by this version; *why
// says what is not (for the log line of a rewrite).
bool IsUsableSequenceCache(const sim::Scenario& scenario, int max_frames, const std::string& dir,
                           std::string* why);

// The sequence of the entry `dir` (checked with IsUsableSequenceCache) as the one
// OpenScenarioSequence gives for `scenario`: the same name, camera, metadata and frames.
bool OpenCachedSequence(const sim::Scenario& scenario, int max_frames, const std::string& dir,
                        StereoSequence* sequence, std::string* error);

// The entry of `scenario` in `cache_dir` (created when missing), simulated by the first caller
// and read by every one (see the top of this file); `progress` for the simulation.
bool OpenSharedScenarioSequence(const sim::Scenario& scenario, int max_frames,
                                const std::string& cache_dir, bool progress,
                                StereoSequence* sequence, std::string* error);

// Waits for the lock "<dir>.writer.lock" of a folder that one of several processes writes and
// the others read (a shared sequence or dataset), polling every 100 ms. False when the lock
// cannot be made, or on SIGINT/SIGTERM while waiting.
bool LockSharedFolder(const std::string& dir, FolderLock* lock, std::string* error);

}  // namespace harness
