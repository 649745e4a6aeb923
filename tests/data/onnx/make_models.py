#!/usr/bin/env python3
"""Writes the test networks of OpenABLE's ONNX descriptor and PyTorch's outputs on real frames.

Three small networks of the families users bring, with random weights of a fixed seed (what is
tested is that OpenCV's DNN module computes what PyTorch computes, not what the weights learnt):

  netvlad.onnx     a convolutional backbone with a NetVLAD head (Arandjelovic et al., CVPR
                   2016): soft assignment by a 1x1 convolution and a softmax over the clusters,
                   residuals to the centroids summed over the positions, intra-normalisation
                   (each cluster's residual L2-normalised), then the whole vector L2-normalised.
  gem.onnx         the same kind of backbone with generalised-mean pooling (Radenovic et al.,
                   TPAMI 2019; p = 3), then L2-normalised.
  projection.onnx  a backbone, global average pooling and a linear projection, not normalised.

Input: 1 x 3 x 32 x 64 (N x C x H x W), RGB, scaled to [0, 1] then standardised with
ImageNet's mean and standard deviation, as torchvision's models expect. The frames are the
bundled Nordland sample's (examples/data/nordland_sample/summer, 64 x 32 pixels: no resizing,
so the input is computed exactly in NumPy), 16 distinct ones spread over it (frames.txt). For each
network it writes NAME.onnx and NAME_outputs.npy (16 x D float32, PyTorch's outputs on those
frames).

Two more networks, for the refusals: fixed_input.onnx (a linear layer over the flattened
3 x 8 x 8 image: it refuses any other input size) and feature_map.onnx (a convolution: its
output is a map per image, not one vector).

Run with Debian's python3-torch and python3-onnx (used only to make these files):
    python3 tests/data/onnx/make_models.py
The files it writes are committed; tests never run it.
"""
import os
import sys

import numpy as np
import torch
import torch.nn.functional as F
from PIL import Image

HERE = os.path.dirname(os.path.abspath(__file__))
SAMPLE = os.path.join(HERE, "..", "..", "..", "examples", "data", "nordland_sample", "summer")
MEAN = np.array([0.485, 0.456, 0.406], np.float32)
STD = np.array([0.229, 0.224, 0.225], np.float32)
FRAMES = 16
OPSET = 10


def backbone():
    return torch.nn.Sequential(
        torch.nn.Conv2d(3, 16, 3, padding=1), torch.nn.ReLU(), torch.nn.MaxPool2d(2),
        torch.nn.Conv2d(16, 32, 3, padding=1), torch.nn.BatchNorm2d(32), torch.nn.ReLU(),
        torch.nn.MaxPool2d(2),
        torch.nn.Conv2d(32, 32, 3, padding=1), torch.nn.ReLU())


class NetVlad(torch.nn.Module):
    """NetVLAD written with the operations OpenCV 4.6's importer runs: 4-D tensors, products
    of tensors of one shape, constant 1x1 convolutions to copy and to sum channel groups, and
    global average pooling (times the positions) for sums over the image. The same function as
    the usual form, V(k) = sum_i a_k(i) (f(i) - c_k), whose export OpenCV 4.6 cannot run (it
    does not broadcast a product of two computed tensors across channels; docs/descriptors.md)."""

    def __init__(self, clusters=8, dim=32):
        super().__init__()
        self.features = backbone()
        self.assign = torch.nn.Conv2d(dim, clusters, 1)
        # near the unit sphere's centre, as the normalised features are spread around it
        self.centroids = torch.nn.Parameter(0.1 * torch.randn(clusters, dim))
        self.clusters, self.dim = clusters, dim
        k, d = clusters, dim
        # Constant 1x1 convolutions: channel c of the outputs below is cluster c // d and
        # feature c % d.
        copy_f = torch.zeros(k * d, d, 1, 1)    # f -> f repeated k times
        copy_a = torch.zeros(k * d, k, 1, 1)    # a -> a_k repeated d times
        group = torch.zeros(k, k * d, 1, 1)     # k*d channels -> the sum of each cluster's d
        for c in range(k * d):
            copy_f[c, c % d] = 1.0
            copy_a[c, c // d] = 1.0
            group[c // d, c] = 1.0
        self.register_buffer("copy_f", copy_f)
        self.register_buffer("copy_a", copy_a)
        self.register_buffer("group", group)

    def forward(self, x):
        f = F.normalize(self.features(x), p=2, dim=1)            # N x D x H x W
        a = F.softmax(self.assign(f), dim=1)                      # N x K x H x W
        positions = float(f.shape[2] * f.shape[3])
        fa = F.conv2d(f, self.copy_f) * F.conv2d(a, self.copy_a)  # a_k(i) f(i), N x KD x H x W
        mass = F.conv2d(F.adaptive_avg_pool2d(a, 1), self.copy_a)  # mean of a_k, N x KD x 1 x 1
        c = self.centroids.reshape(1, -1, 1, 1)
        v = (F.adaptive_avg_pool2d(fa, 1) - mass * c) * positions  # N x KD x 1 x 1
        # Intra-normalisation: each cluster's D values divided by their L2 norm.
        norm = torch.sqrt(F.conv2d(v * v, self.group).clamp(min=1e-24))  # N x K x 1 x 1
        v = v / F.conv2d(norm, self.copy_a)
        return F.normalize(v.flatten(1), p=2, dim=1)

    def reference(self, x):
        """The usual form, for the check below."""
        f = F.normalize(self.features(x), p=2, dim=1)
        n = f.shape[0]
        a = F.softmax(self.assign(f), dim=1).reshape(n, self.clusters, -1)
        f = f.reshape(n, self.dim, -1)
        vlad = torch.matmul(a, f.transpose(1, 2)) - a.sum(dim=2, keepdim=True) * self.centroids
        vlad = F.normalize(vlad, p=2, dim=2)
        return F.normalize(vlad.reshape(n, -1), p=2, dim=1)


class Gem(torch.nn.Module):
    def __init__(self, p=3.0):
        super().__init__()
        self.features = backbone()
        self.p = p

    def forward(self, x):
        f = self.features(x).clamp(min=1e-6).pow(self.p)
        g = F.adaptive_avg_pool2d(f, 1).pow(1.0 / self.p).flatten(1)
        return F.normalize(g, p=2, dim=1)


class Projection(torch.nn.Module):
    def __init__(self, out=24):
        super().__init__()
        self.features = backbone()
        self.fc = torch.nn.Linear(32, out)

    def forward(self, x):
        return self.fc(F.adaptive_avg_pool2d(self.features(x), 1).flatten(1))


def frames_input():
    # Every 17th frame from the 21st on: the sample's first 17 frames are one image (the train
    # standing), and vectors of one image would test nothing.
    names = sorted(os.listdir(SAMPLE))[20::17][:FRAMES]
    images = [np.asarray(Image.open(os.path.join(SAMPLE, n)).convert("RGB"), np.float32)
              for n in names]
    assert len({im.tobytes() for im in images}) == FRAMES, "frames that repeat"
    x = (np.stack(images) / 255.0 - MEAN) / STD                   # N x H x W x 3, RGB
    return np.ascontiguousarray(x.transpose(0, 3, 1, 2), np.float32), names


def main():
    torch.manual_seed(20261129)
    x, names = frames_input()
    with open(os.path.join(HERE, "frames.txt"), "w") as f:
        f.write("\n".join(names) + "\n")
    for name, net in (("netvlad", NetVlad()), ("gem", Gem()), ("projection", Projection())):
        net.eval()
        for m in net.modules():  # batch norm with statistics of its own, not the identity
            if isinstance(m, torch.nn.BatchNorm2d):
                m.running_mean.uniform_(-0.5, 0.5)
                m.running_var.uniform_(0.5, 2.0)
        with torch.no_grad():
            out = net(torch.from_numpy(x)).numpy().astype(np.float32)
            if hasattr(net, "reference"):  # the exported form is the usual NetVLAD
                usual = net.reference(torch.from_numpy(x)).numpy()
                assert np.abs(out - usual).max() < 1e-5, np.abs(out - usual).max()
        # Vectors that differ from frame to frame (the smallest distance between two of them
        # 1/200 of the largest at least): a network that gave one vector for every frame
        # would let a wrong preprocessing pass.
        d = np.sqrt(((out[:, None, :].astype(np.float64) - out[None]) ** 2).sum(axis=2))
        pairs = d[np.triu_indices(FRAMES, 1)]
        assert pairs.min() > 0.005 * pairs.max(), (name, pairs.min(), pairs.max())
        np.save(os.path.join(HERE, name + "_outputs.npy"), out)
        torch.onnx.export(net, torch.from_numpy(x[:1]), os.path.join(HERE, name + ".onnx"),
                          opset_version=OPSET, input_names=["image"], output_names=["descriptor"],
                          dynamic_axes={"image": {0: "batch"}, "descriptor": {0: "batch"}})
        print("%s: %d x %d outputs, %d bytes" % (name, out.shape[0], out.shape[1],
                                                 os.path.getsize(os.path.join(HERE,
                                                                              name + ".onnx"))))
    fixed = torch.nn.Sequential(torch.nn.Flatten(), torch.nn.Linear(3 * 8 * 8, 16))
    feature_map = torch.nn.Conv2d(3, 4, 3, padding=1)
    for name, net, shape in (("fixed_input", fixed, (1, 3, 8, 8)),
                             ("feature_map", feature_map, (1, 3, 32, 64))):
        torch.onnx.export(net.eval(), torch.zeros(shape), os.path.join(HERE, name + ".onnx"),
                          opset_version=OPSET, input_names=["image"], output_names=["out"],
                          dynamic_axes={"image": {0: "batch"}, "out": {0: "batch"}})
    return 0


if __name__ == "__main__":
    sys.exit(main())
