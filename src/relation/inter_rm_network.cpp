// InterRM's network (Ret3D §3.3, eqs. (6)-(9)) and its model file.
#include "inter_rm_network.h"

#include <cmath>
#include <stdexcept>

#include "ret3d/core/geometry.h"

namespace ret3d {
namespace relation {

namespace {

bool finite(const Box& b) {
  return std::isfinite(b.x) && std::isfinite(b.y) && std::isfinite(b.z) && std::isfinite(b.length) &&
         std::isfinite(b.width) && std::isfinite(b.height) && std::isfinite(b.yaw) && std::isfinite(b.vx) &&
         std::isfinite(b.vy) && std::isfinite(b.score) && b.length > 0 && b.width > 0 && b.height > 0;
}

}  // namespace

void interBasicFeatures(const InterRMSequence& seq, std::size_t k, float* out) {
  const Box& c = seq.boxes[0];
  const Box& e = seq.boxes[k];
  const double cs = std::cos(c.yaw), sn = std::sin(c.yaw);
  const double ex = e.x - c.x, ey = e.y - c.y;
  // Rotate by -yaw_c: the current box's frame.
  out[0] = static_cast<float>(cs * ex + sn * ey);
  out[1] = static_cast<float>(-sn * ex + cs * ey);
  out[2] = static_cast<float>(e.z - c.z);
  out[3] = static_cast<float>(std::log(e.length));
  out[4] = static_cast<float>(std::log(e.width));
  out[5] = static_cast<float>(std::log(e.height));
  out[6] = static_cast<float>(std::sin(e.yaw - c.yaw));
  out[7] = static_cast<float>(std::cos(e.yaw - c.yaw));
  out[8] = static_cast<float>(cs * e.vx + sn * e.vy);
  out[9] = static_cast<float>(-sn * e.vx + cs * e.vy);
  out[10] = e.score;
  out[11] = e.label == ObjectClass::Car ? 1.f : 0.f;
  out[12] = e.label == ObjectClass::Pedestrian ? 1.f : 0.f;
  out[13] = e.label == ObjectClass::Cyclist ? 1.f : 0.f;
  out[14] = static_cast<float>(seq.dt[k]);  // the implicit positional encoding (Table 4)
  out[15] = static_cast<float>(std::hypot(e.x, e.y));
}

InterRMInputs makeInterRMInputs(const std::vector<const InterRMSequence*>& sequences, int max_history) {
  const int64_t B = static_cast<int64_t>(sequences.size());
  int64_t L = 1;
  for (std::size_t i = 0; i < sequences.size(); ++i) {
    const InterRMSequence& s = *sequences[i];
    if (s.boxes.empty()) throw std::invalid_argument("InterRM: sequence " + std::to_string(i) + " is empty");
    if (s.dt.size() != s.boxes.size())
      throw std::invalid_argument("InterRM: sequence " + std::to_string(i) + " has " + std::to_string(s.boxes.size()) +
                                  " boxes but " + std::to_string(s.dt.size()) + " time offsets");
    for (std::size_t k = 0; k < s.boxes.size(); ++k)
      if (!finite(s.boxes[k]) || !std::isfinite(s.dt[k]))
        throw std::invalid_argument("InterRM: sequence " + std::to_string(i) + " entry " + std::to_string(k) +
                                    " has a non-finite field or a non-positive size");
    L = std::max<int64_t>(L, std::min<int64_t>(static_cast<int64_t>(s.boxes.size()), max_history));
  }
  InterRMInputs in;
  in.features = torch::zeros({B, L, kInterBasicFeatures});
  in.padding = torch::ones({B, L}, torch::kBool);
  in.dt = torch::zeros({B, L});
  in.position = torch::zeros({B, L, 2});
  float* f = in.features.data_ptr<float>();
  bool* pad = in.padding.data_ptr<bool>();
  float* dt = in.dt.data_ptr<float>();
  float* pos = in.position.data_ptr<float>();
  for (int64_t b = 0; b < B; ++b) {
    const InterRMSequence& s = *sequences[static_cast<std::size_t>(b)];
    const int64_t n = std::min<int64_t>(static_cast<int64_t>(s.boxes.size()), max_history);
    for (int64_t k = 0; k < n; ++k) {
      const int64_t row = b * L + k;
      interBasicFeatures(s, static_cast<std::size_t>(k), f + row * kInterBasicFeatures);
      pad[row] = false;
      dt[row] = static_cast<float>(s.dt[static_cast<std::size_t>(k)]);
      pos[row * 2] = static_cast<float>(s.boxes[static_cast<std::size_t>(k)].x);
      pos[row * 2 + 1] = static_cast<float>(s.boxes[static_cast<std::size_t>(k)].y);
    }
  }
  return in;
}

InterRMNetImpl::InterRMNetImpl(const InterRMArch& a) : arch(a) {
  arch.validate();
  const int64_t C = arch.c_enc, F = kInterBasicFeatures;
  feat_mean = register_buffer("feat_mean", torch::zeros({F}));
  feat_std = register_buffer("feat_std", torch::ones({F}));
  encode = register_module("encode", torch::nn::Linear(F, C));
  wq = register_module("wq", torch::nn::Linear(C, C));
  wk = register_module("wk", torch::nn::Linear(C, C));
  wv = register_module("wv", torch::nn::Linear(C, C));
  wo = register_module("wo", torch::nn::Linear(C, C));
  ffn1 = register_module("ffn1", torch::nn::Linear(C, C * arch.ffn_expansion));
  ffn2 = register_module("ffn2", torch::nn::Linear(C * arch.ffn_expansion, C));
  head = register_module("head", torch::nn::Linear(C, kInterOutputs));
  // The regression starts at zero: an untrained module leaves the boxes as they are.
  torch::NoGradGuard g;
  head->weight.zero_();
  head->bias.zero_();
}

torch::Tensor InterRMNetImpl::positionalEncoding(const InterRMInputs& in) const {
  const int64_t C = arch.c_enc;
  const auto B = in.dt.size(0), L = in.dt.size(1);
  if (arch.positional_encoding == InterPositionalEncoding::Temporal) {
    // Transformer sinusoids of the time offset counted in 0.1 s steps (one frame at 10 Hz).
    const torch::Tensor freq = torch::exp(torch::arange(0, C / 2, torch::kFloat) * (-std::log(10000.0) * 2.0 / C));
    const torch::Tensor arg = (in.dt / 0.1).unsqueeze(-1) * freq;  // B x L x C/2
    return torch::stack({arg.sin(), arg.cos()}, -1).reshape({B, L, C});
  }
  if (arch.positional_encoding == InterPositionalEncoding::Spatial) {
    // Sinusoids of the sensor-frame x and y (0.1 m units), half of the channels each.
    const torch::Tensor freq = torch::exp(torch::arange(0, C / 4, torch::kFloat) * (-std::log(10000.0) * 4.0 / C));
    std::vector<torch::Tensor> parts;
    for (int d = 0; d < 2; ++d) {
      const torch::Tensor arg = (in.position.select(2, d) / 0.1).unsqueeze(-1) * freq;  // B x L x C/4
      parts.push_back(torch::stack({arg.sin(), arg.cos()}, -1).reshape({B, L, C / 2}));
    }
    return torch::cat(parts, -1);
  }
  return {};
}

torch::Tensor InterRMNetImpl::forward(const InterRMInputs& in) {
  const int64_t C = arch.c_enc, H = arch.heads, dh = C / H;
  const auto B = in.features.size(0), L = in.features.size(1);
  const torch::Tensor pad = in.padding;
  const torch::Tensor x = ((in.features - feat_mean) / feat_std).masked_fill(pad.unsqueeze(-1), 0.0);
  const torch::Tensor pe = positionalEncoding(in);

  // Eq. (6): D = X W^e (+ an explicit positional encoding, Table 4). Only row 0 (the current box) is needed whole.
  torch::Tensor d0 = encode(x.select(1, 0));
  if (pe.defined()) d0 = d0 + pe.select(1, 0);
  // Eq. (7): K = D W^k, V = D W^v for every entry. D is linear in the F-dimensional inputs, so W^k W^e is applied to
  // X directly: the same values at F/C of the cost, which keeps 50 tracks of 30 entries within the real-time budget.
  auto project = [&](const torch::nn::Linear& w) {
    const torch::Tensor weight = w->weight.mm(encode->weight);             // C x F
    const torch::Tensor bias = w->weight.mv(encode->bias) + w->bias;       // C
    torch::Tensor out = torch::matmul(x, weight.t()) + bias;               // B x L x C
    if (pe.defined()) out = out + torch::matmul(pe, w->weight.t());
    return out;
  };
  const torch::Tensor k = project(wk), v = project(wv);
  const torch::Tensor q = wq(d0);  // B x C, the current entry's query

  // Eq. (8) per head, for the current entry's query; padded keys get no weight.
  const torch::Tensor qh = q.view({B, H, 1, dh});
  const torch::Tensor kh = k.view({B, L, H, dh}).permute({0, 2, 3, 1});  // B x H x dh x L
  const torch::Tensor vh = v.view({B, L, H, dh}).transpose(1, 2);        // B x H x L x dh
  torch::Tensor scores = torch::matmul(qh, kh) / std::sqrt(static_cast<double>(dh));  // B x H x 1 x L
  scores = scores.masked_fill(pad.view({B, 1, 1, L}), -std::numeric_limits<float>::infinity());
  const torch::Tensor attn = torch::softmax(scores, -1);
  const torch::Tensor a = wo(torch::matmul(attn, vh).reshape({B, C}));  // A (current row), heads concatenated

  // Eq. (9): A' = FFN(A + D) + A + D.
  const torch::Tensor s = a + d0;
  const torch::Tensor a_ref = ffn2(torch::relu(ffn1(s))) + s;
  return head(a_ref);
}

std::vector<Box> applyInterRMOutput(const std::vector<const InterRMSequence*>& sequences, const torch::Tensor& out,
                                    bool apply_size) {
  const torch::Tensor o = out.to(torch::kDouble).contiguous();
  const auto acc = o.accessor<double, 2>();
  std::vector<Box> boxes;
  boxes.reserve(sequences.size());
  for (std::size_t i = 0; i < sequences.size(); ++i) {
    Box b = sequences[i]->boxes[0];
    const int64_t r = static_cast<int64_t>(i);
    const double cs = std::cos(b.yaw), sn = std::sin(b.yaw);
    b.x += cs * acc[r][0] - sn * acc[r][1];
    b.y += sn * acc[r][0] + cs * acc[r][1];
    b.z += acc[r][2];
    // Clamped like the targets can be: a size change beyond e^{+-1} is not a refinement.
    if (apply_size) {
      b.length *= std::exp(std::clamp(acc[r][3], -1.0, 1.0));
      b.width *= std::exp(std::clamp(acc[r][4], -1.0, 1.0));
      b.height *= std::exp(std::clamp(acc[r][5], -1.0, 1.0));
    }
    b.yaw = wrapAngle(b.yaw + std::clamp(acc[r][6], -M_PI / 2, M_PI / 2));
    boxes.push_back(b);
  }
  return boxes;
}

// ---- model file ----

template class RelationModule<InterRMImpl, InterRMConfig>;

InterRMModelInfo readInterRMModelInfo(const std::string& path) { return readModuleInfo<InterRMImpl>(path); }

}  // namespace relation
}  // namespace ret3d
