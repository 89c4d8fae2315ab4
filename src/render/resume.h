// Resuming a render (`--checkpoint` writes the state, `--resume FILE` continues from it;
// docs/DISTRIBUTED.md, "Resume"): where a render stands after a pass (RenderSnapshot: passes,
// spp, seconds, path statistics, the film's exact sums, the render loop's own state and the
// guide's complete learning state), and its file, which also holds a fingerprint of the scene
// and the options that must match (key/value pairs that the command line chooses) and a
// checksum. The render loop takes a snapshot after a pass (RenderOptions::onSnapshot) and
// continues from one (RenderOptions::resume) as the uninterrupted render would have.
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "render/integrator.h"

namespace rlpbrt {

struct RenderSnapshot {
    int passes = 0;          // passes done
    int spp = 0;             // samples per pixel done
    double seconds = 0.0;    // render time so far (a time budget counts it)
    PathStats stats;         // of all ranks
    double guideEndPassSeconds = 0.0;  // RenderResult's, so far
    int ranks = 1;           // processes that rendered (a different count resumes, not bitwise)
    // The render loop's state: whether guided passes continue (the auto trial may have ended
    // them), its verdict, and learn=N's spp at which learning stopped (frozen: it has).
    bool guided = false;
    bool autoRan = false, autoKept = true;
    int autoGuidedSpp = 0;
    double autoGuidedCost = 0.0, autoPlainCost = 0.0;
    int autoPlainSpp = 0;
    bool frozen = false;
    int learningSpp = 0;
    // The auto trial under way (0: none or over; 1: waiting for its guided pass; 2: its guided
    // pass measured, the plain one next; 3: the plain pass's first part measured, its rest
    // next): PassMoments::state of the pixel means so far, of the guided pass and of the plain
    // part, the guided pass's CPU seconds per sample and spp, the plain part's CPU seconds and
    // spp.
    int trial = 0;
    std::string trialHistory, trialGuided, trialPlain;
    double trialGuidedSecondsPerSample = 0.0;
    int trialGuidedCount = 0;
    double trialPlainSeconds = 0.0;
    int trialPlainCount = 0;
    std::vector<double> film;       // Film::sums()
    std::vector<float> estimates;   // the adjoint roulette's pixel estimates (empty: none yet)
    std::string guide;              // GuidingField::saveState (empty without a guide)
};

// What must match between the run that wrote a state and the run that resumes it, in order.
using ResumeFingerprint = std::vector<std::pair<std::string, std::string>>;

// The file: magic "RLPBRSUM", u32 version, the fingerprint, the snapshot, and an FNV-1a
// checksum of all of it (docs/DISTRIBUTED.md). Written atomically (temporary file + rename).
bool writeResumeFile(const std::string& path, const ResumeFingerprint& fingerprint,
                     const RenderSnapshot& snapshot, std::string* error);
// Reads a file written by writeResumeFile; false and *error (naming the file and what is
// wrong: missing, not a resume file, another version, truncated, corrupt) otherwise.
bool readResumeFile(const std::string& path, ResumeFingerprint* fingerprint,
                    RenderSnapshot* snapshot, std::string* error);
// "" if `now` matches `saved`, else the differences, e.g. "--spp is 64 here, 32 in the file".
std::string fingerprintMismatch(const ResumeFingerprint& saved, const ResumeFingerprint& now);

// 64-bit FNV-1a of bytes (the file's checksum, and the scene file's fingerprint).
uint64_t fnv1a(const std::string& bytes, uint64_t hash = 0xcbf29ce484222325ull);

}  // namespace rlpbrt
