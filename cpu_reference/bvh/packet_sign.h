/// @file packet_sign.h
/// @brief The sign of the CPU BVH sampler's packets of kCpuPacketLanes points (lattice bricks,
/// Morton packets of a point list): the pseudonormal sign per point, or the winding sign of
/// all lanes at once.
#pragma once

#include "core/sampling/sampler_sign.h"
#include "cpu_reference/dispatch/cpu_kernels.h"
#include "kernels/winding/certified_winding_packet.h"

namespace sdf {

/// The sign of a packet's lanes. With the samplers' winding sign (certified: the exact side,
/// certified_winding_packet.h) the sides of the packet's lanes come from one traversal per
/// stage of the certified ladder, each lane's side and stage what WindingSign::side() gives
/// its point; uncertified (measurements), the fast winding numbers of all kCpuPacketLanes
/// lanes come from one traversal (fast_winding_packet.h), each lane's value the bits
/// WindingSign::side() computes; otherwise each point gets SamplerSign::apply().
class PacketSign {
public:
    explicit PacketSign(const SamplerSign& sign) : sign_(sign) {
        winding_ = sign.winding() ? sign.winding_sign() : nullptr;
    }

    /// Evaluates the sides of the packet's points `position`: the first `count` lanes are
    /// points (counted), the others spare.
    void prepare(const Vec3d* position, int count) {
        if (winding_ == nullptr) return;
        const WindingSignOptions& o = winding_->options();
        if (o.certify) {
            WindingSide side[kCpuPacketLanes];
            certified_winding_sides_packet<kCpuPacketLanes>(winding_->view(), position, count, o.accuracy, o.certification, side);
            int64_t stages[kWindingStages] = {};
            for (int k = 0; k < count; ++k) {
                inside_[k] = side[k].inside;
                ++stages[int(side[k].stage)];
            }
            for (int s = 0; s < kWindingStages; ++s)
                if (stages[s] > 0) winding_->count(WindingStage(s), stages[s]);
            return;
        }
        double px[kCpuPacketLanes], py[kCpuPacketLanes], pz[kCpuPacketLanes], w[kCpuPacketLanes];
        for (int k = 0; k < kCpuPacketLanes; ++k) {
            px[k] = position[k].x;
            py[k] = position[k].y;
            pz[k] = position[k].z;
        }
        kernel_(winding_->view(), px, py, pz, o.accuracy, w);
        for (int k = 0; k < kCpuPacketLanes; ++k) inside_[k] = w[k] > 0.5;  // WindingSign::side()
        winding_->count(WindingStage::Fast, count);
    }

    /// Lane k's sample `s` at p with its sign (after prepare() of its packet).
    SignedDistanceSample<double> apply(const SignedDistanceSample<double>& s, int k, const Vec3d& p) const {
        return winding_ != nullptr ? with_sign(s, inside_[k]) : sign_.apply(s, p);
    }

private:
    const SamplerSign& sign_;
    const WindingSign* winding_ = nullptr;  ///< non-null: packets of winding numbers
    WindingPacketFn kernel_ = active_cpu_kernels().winding_numbers_packet;
    bool inside_[kCpuPacketLanes] = {};
};

}  // namespace sdf
