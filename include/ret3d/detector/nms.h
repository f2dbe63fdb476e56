// Rotated non-maximum suppression on exact BEV IoU (core bevIoU), per class.
#pragma once

#include <cstddef>
#include <vector>

#include "ret3d/core/types.h"

namespace ret3d {

// Indices of the boxes kept, by descending score: a box is dropped when its BEV IoU with a kept box of the same
// class exceeds iou_threshold (with per_class = false, of any class). At most max_keep (0 = no limit).
std::vector<std::size_t> rotatedNms(const std::vector<Box>& boxes, double iou_threshold, bool per_class = true,
                                    std::size_t max_keep = 0);

// Box voting: the box boxes[keep[k]] replaced by the score-weighted mean of the boxes of its class (all of `boxes`,
// suppressed ones included) whose BEV IoU with it is at least iou_threshold. Centre, log sizes and velocity are
// averaged; yaw as the kept yaw plus the mean difference taken modulo pi (a flipped neighbour still votes for the
// same axis); score and label stay those of the kept box.
std::vector<Box> voteBoxes(const std::vector<Box>& boxes, const std::vector<std::size_t>& keep, double iou_threshold);

}  // namespace ret3d
