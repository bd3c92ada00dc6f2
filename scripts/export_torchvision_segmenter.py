"""Exports a torchvision segmentation network to ONNX for OpenCV 4.6 and writes its model card.

Called by scripts/export-torchvision-segmenter (which installs Debian's python3-torch,
python3-torchvision, python3-onnx and python3-opencv first). Builds torchvision's
lraspp_mobilenet_v3_large or deeplabv3_mobilenet_v3_large with N classes (no pretrained
weights are downloaded), loads a state_dict when given, exports ONNX at a fixed 1x3xHxW input
with constant folding, removes the Identity nodes OpenCV 4.6 cannot load (torch shares equal
tensors through them, which an untrained network is full of), checks that OpenCV's DNN module
loads the file and agrees with torch on a random input, and writes the card next to it.
"""

import argparse
import os
import subprocess
import sys
import time
import warnings

import numpy as np
import onnx
import torch
import torchvision
from onnx import numpy_helper
from torchvision.models import segmentation

ARCHS = {
    "lraspp": ("lraspp_mobilenet_v3_large", "LR-ASPP MobileNetV3-Large",
               segmentation.lraspp_mobilenet_v3_large),
    "deeplabv3": ("deeplabv3_mobilenet_v3_large", "DeepLabV3 MobileNetV3-Large",
                  segmentation.deeplabv3_mobilenet_v3_large),
}
# torchvision's ImageNet normalisation, RGB, on the 0..1 scale.
MEAN = (0.485, 0.456, 0.406)
STD = (0.229, 0.224, 0.225)
# OpenCV's output may differ from torch's by float rounding only: at most this share of the
# largest logit (plus a floor for networks whose logits are all near zero).
TOLERANCE = 1e-3
FLOOR = 1e-5


def fail(message):
    sys.exit(f"export-torchvision-segmenter: {message}")


class LogitsOnly(torch.nn.Module):
    """torchvision's segmentation models return a dict; the card wants one [1, C, H, W] output."""

    def __init__(self, model):
        super().__init__()
        self.model = model

    def forward(self, x):
        return self.model(x)["out"]


def load_weights(model, path):
    state = torch.load(path, map_location="cpu")
    if isinstance(state, dict) and "model" in state and isinstance(state["model"], dict):
        state = state["model"]  # a checkpoint of torchvision's reference training scripts
    if not isinstance(state, dict):
        fail(f"{path}: not a state_dict (a dict of tensors), got {type(state).__name__}")
    aux = [k for k in state if k.startswith("aux_classifier.")]
    for k in aux:
        del state[k]  # the auxiliary head is for training only; the export has none
    try:
        model.load_state_dict(state, strict=True)
    except RuntimeError as e:
        fail(f"{path}: does not fit the network with --classes as given:\n{e}")
    return len(aux)


def remove_identities(model_proto):
    """Removes every Identity node. OpenCV 4.6 fails on an Identity whose input is an
    initializer ("Identity ... inputs.size()"): torch's exporter deduplicates equal weight
    tensors (an untrained network's zero biases and unit scales) and feeds the copies through
    Identity nodes. An Identity fed by an initializer becomes its own initializer (a copy of
    the tensor under the Identity's output name); any other Identity is bypassed."""
    graph = model_proto.graph
    initializers = {t.name: t for t in graph.initializer}
    graph_outputs = {o.name for o in graph.output}
    rename = {}
    kept = []
    copies = 0
    for node in graph.node:
        if node.op_type != "Identity":
            kept.append(node)
            continue
        source = rename.get(node.input[0], node.input[0])
        target = node.output[0]
        if source in initializers:
            tensor = numpy_helper.to_array(initializers[source]).copy()
            copy = numpy_helper.from_array(tensor, name=target)
            graph.initializer.append(copy)
            initializers[target] = copy
            copies += 1
        elif target in graph_outputs:
            kept.append(node)  # the graph's output must keep its name
        else:
            rename[target] = source
    for node in kept:
        for i, name in enumerate(node.input):
            if name in rename:
                node.input[i] = rename[name]
    removed = len(graph.node) - len(kept)
    del graph.node[:]
    graph.node.extend(kept)
    # Initializers no node reads any more (the shared originals, when every user was an
    # Identity) would only make the file bigger.
    used = {name for node in graph.node for name in node.input}
    unused = [t for t in graph.initializer if t.name not in used]
    for t in unused:
        graph.initializer.remove(t)
    return removed, copies


def verify_with_opencv(onnx_file, model, width, height, threads):
    import cv2  # Debian's python3-opencv: the same OpenCV 4.6 the robot links

    cv2.setNumThreads(threads)
    try:
        net = cv2.dnn.readNetFromONNX(onnx_file)
    except cv2.error as e:
        fail(f"OpenCV {cv2.__version__} does not load {onnx_file}:\n{e}")
    generator = torch.Generator().manual_seed(0)
    pixels = torch.rand(1, 3, height, width, generator=generator)
    x = (pixels - torch.tensor(MEAN).view(1, 3, 1, 1)) / torch.tensor(STD).view(1, 3, 1, 1)
    with torch.no_grad():
        expected = model(x).numpy()
    net.setInput(x.numpy())
    got = net.forward()  # the first pass also sets the network up
    start = time.perf_counter()
    net.setInput(x.numpy())
    got = net.forward()
    forward_ms = 1e3 * (time.perf_counter() - start)
    if got.shape != expected.shape:
        fail(f"OpenCV's output shape {got.shape} differs from torch's {expected.shape}")
    diff = float(np.abs(got - expected).max())
    scale = float(np.abs(expected).max())
    print(f"export-torchvision-segmenter: OpenCV {cv2.__version__} loads {onnx_file}; output "
          f"{list(got.shape)}; max abs diff to torch on a random input {diff:.3g} "
          f"(largest logit {scale:.3g}); OpenCV forward {forward_ms:.0f} ms on {threads} threads")
    if not diff <= TOLERANCE * scale + FLOOR:
        fail(f"OpenCV and torch disagree by {diff:.3g} (allowed {TOLERANCE * scale + FLOOR:.3g})")
    return diff, scale


# Cityscapes' 19 training classes in train-id order and their official colours (the same as
# models/enet-cityscapes.yaml): --names cityscapes.
CITYSCAPES = [
    ("road", (128, 64, 128)), ("sidewalk", (244, 35, 232)), ("building", (70, 70, 70)),
    ("wall", (102, 102, 156)), ("fence", (190, 153, 153)), ("pole", (153, 153, 153)),
    ("traffic light", (250, 170, 30)), ("traffic sign", (220, 220, 0)),
    ("vegetation", (107, 142, 35)), ("terrain", (152, 251, 152)), ("sky", (70, 130, 180)),
    ("person", (220, 20, 60)), ("rider", (255, 0, 0)), ("car", (0, 0, 142)),
    ("truck", (0, 0, 70)), ("bus", (0, 60, 100)), ("train", (0, 80, 100)),
    ("motorcycle", (0, 0, 230)), ("bicycle", (119, 11, 32)),
]


def palette(n):
    """Distinct colours for generic classes: hues around the circle, two brightnesses."""
    import colorsys

    colors = []
    for i in range(n):
        h = (i * 0.618033988749895) % 1.0
        v = 0.95 if i % 2 == 0 else 0.7
        r, g, b = colorsys.hsv_to_rgb(h, 0.8, v)
        colors.append((round(255 * r), round(255 * g), round(255 * b)))
    return colors


def write_card(path, args, arch_title, onnx_name, width, height, names, parameters, removed,
               copies, diff, scale, aux_dropped):
    random = args.weights is None
    lines = [f"# Model card of torchvision's {arch_title} ({ARCHS[args.arch][0]}),",
             f"# {len(names)} classes, exported to ONNX by scripts/export-torchvision-segmenter:",
             f"# torchvision {torchvision.__version__}, torch {torch.__version__}, onnx "
             f"{onnx.__version__}, opset {args.opset},",
             f"# fixed input 1x3x{height}x{width}, constant folding, {removed} Identity nodes "
             f"removed ({copies} shared",
             "# initializers copied: OpenCV 4.6 cannot load them, docs/models.md);"
             f" {parameters} parameters.",
             f"# OpenCV agreed with torch on a random input to {diff:.2g} (largest logit "
             f"{scale:.2g})."]
    if random:
        lines += ["#",
                  "# RANDOM WEIGHTS: exported without --weights. This network labels nothing;",
                  "# it is for compatibility and speed checks only (semap-segment --check,",
                  "# perception_bench --model-card)."
                  + (" The class names are placeholders." if not args.names else "")]
    else:
        lines += [f"# Weights: {os.path.abspath(args.weights)}"
                  + (f" ({aux_dropped} aux_classifier tensors not exported)" if aux_dropped
                     else "") + "."]
    lines += ["#",
              "# The map: model class i feeds map class i + 1 (K = classes + 1, class 0 is free",
              "# space). Edit map: to feed the robot's own classes (docs/models.md).",
              "",
              f"model: {onnx_name}",
              "format: onnx",
              "",
              "input:",
              f"  width: {width}",
              f"  height: {height}",
              "  channel_order: rgb",
              "  mean: [" + ", ".join(f"{m}" for m in MEAN) + "]   # torchvision's ImageNet "
              "normalisation",
              "  std: [" + ", ".join(f"{s}" for s in STD) + "]",
              "",
              "output: logits",
              "threads: 2",
              "",
              "model_classes:",
              "  names: [" + ", ".join(names) + "]",
              "  colors: [" + ",   ".join(f"{r}, {g}, {b}" for r, g, b in args.colors) + "]",
              "",
              "map:",
              f"  num_classes: {len(names) + 1}",
              "  from_model:"]
    lines += [f"    {name}: {i + 1}" for i, name in enumerate(names)]
    lines.append("  unmapped: drop")
    with open(path, "w") as f:
        f.write("\n".join(lines) + "\n")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--arch", required=True, choices=sorted(ARCHS))
    parser.add_argument("--weights", help="a state_dict (.pt) of the network with --classes")
    parser.add_argument("--size", required=True, help="input size WxH, e.g. 640x480")
    parser.add_argument("--classes", required=True, type=int, help="output classes N")
    parser.add_argument("--names", help="class names, comma-separated (default class_0 ...), or "
                        "'cityscapes': the 19 training classes and their palette")
    parser.add_argument("--out", required=True, help="folder for NAME.onnx and NAME.yaml")
    parser.add_argument("--name", help="file stem (default ARCH-mobilenetv3-WxH[-random])")
    parser.add_argument("--opset", type=int, default=11, choices=(11, 13))
    parser.add_argument("--threads", type=int, default=2)
    parser.add_argument("--check-with", help="semap-segment to run --check on the card with")
    args = parser.parse_args()

    try:
        width, height = (int(v) for v in args.size.lower().split("x"))
    except ValueError:
        fail(f"--size: expected WxH, got '{args.size}'")
    if width < 32 or height < 32:
        fail(f"--size: {width}x{height} is too small (at least 32x32)")
    if not 1 <= args.classes <= 255:
        fail(f"--classes: expected 1..255, got {args.classes}")
    args.colors = palette(args.classes)
    if args.names == "cityscapes":
        if args.classes != len(CITYSCAPES):
            fail(f"--names cityscapes: the {len(CITYSCAPES)} training classes, not {args.classes}")
        names = [n for n, _ in CITYSCAPES]
        args.colors = [c for _, c in CITYSCAPES]
    elif args.names:
        names = [n.strip() for n in args.names.split(",")]
        if len(names) != args.classes:
            fail(f"--names: {len(names)} names for {args.classes} classes")
        bad = [n for n in names if not n or any(c in n for c in ":[]{}#,'\"")]
        if bad or len(set(names)) != len(names):
            fail("--names: each name must be unique, non-empty and without YAML punctuation")
    else:
        names = [f"class_{i}" for i in range(args.classes)]

    torch.set_num_threads(args.threads)
    # torch 1.13 warns about constants' shapes at opset 13; the export is checked below anyway.
    warnings.filterwarnings("ignore", message="The shape inference of prim::Constant")
    func_name, arch_title, build = ARCHS[args.arch]
    net = build(weights=None, weights_backbone=None, num_classes=args.classes, aux_loss=False)
    aux_dropped = 0
    if args.weights:
        aux_dropped = load_weights(net, args.weights)
    model = LogitsOnly(net).eval()
    parameters = sum(p.numel() for p in net.parameters())

    stem = args.name or f"{args.arch}-mobilenetv3-{width}x{height}" + (
        "" if args.weights else "-random")
    os.makedirs(args.out, exist_ok=True)
    onnx_file = os.path.join(args.out, stem + ".onnx")
    card_file = os.path.join(args.out, stem + ".yaml")
    with torch.no_grad():
        torch.onnx.export(model, torch.zeros(1, 3, height, width), onnx_file,
                          opset_version=args.opset, do_constant_folding=True,
                          input_names=["image"], output_names=["logits"])
    proto = onnx.load(onnx_file)
    removed, copies = remove_identities(proto)
    onnx.checker.check_model(proto)
    onnx.save(proto, onnx_file)
    print(f"export-torchvision-segmenter: {arch_title}, {args.classes} classes, "
          f"{width}x{height}, opset {args.opset}: {parameters} parameters, {removed} Identity "
          f"nodes removed ({copies} shared initializers copied)")

    diff, scale = verify_with_opencv(onnx_file, model, width, height, args.threads)
    write_card(card_file, args, arch_title, os.path.basename(onnx_file), width, height, names,
               parameters, removed, copies, diff, scale, aux_dropped)
    print(f"export-torchvision-segmenter: wrote {onnx_file} and {card_file}"
          + ("" if args.weights else " (random weights: for compatibility and speed checks only)"))
    if args.check_with:
        # The card through the robot's own parser and segmenter (exit 2 on any problem).
        print(f"export-torchvision-segmenter: {args.check_with} --check {card_file}", flush=True)
        status = subprocess.run([args.check_with, "--check", card_file]).returncode
        if status != 0:
            fail(f"semap-segment --check {card_file} failed (exit {status})")


if __name__ == "__main__":
    main()
