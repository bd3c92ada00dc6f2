"""Trains semap's segmentation network on frames rendered by the simulated camera.

Called by scripts/train-segmenter, which renders the data set first. Reads DATA/{train,val}/
(rgb_NNNNN.ppm and label_NNNNN.pgm, one model class index per pixel, 255 = ignore), trains a
small fully convolutional network on the CPU with fixed seeds, exports it to ONNX (opset 11,
fixed input shape, logits at a quarter of the input size: OpenCV 4.6's DNN reads every op used)
and writes the model card next to it with the validation figures as comments.
"""

import argparse
import glob
import json
import os
import time

import numpy as np
import torch
import torch.nn as nn
import torch.nn.functional as F


def read_netpbm(path):
    """Binary PPM (P6, RGB) or PGM (P5), 8 bits, as written by cv::imwrite."""
    with open(path, "rb") as f:
        data = f.read()
    fields, pos = [], 0
    while len(fields) < 4:
        while data[pos:pos + 1].isspace():
            pos += 1
        if data[pos:pos + 1] == b"#":
            pos = data.index(b"\n", pos)
            continue
        end = pos
        while not data[end:end + 1].isspace():
            end += 1
        fields.append(data[pos:end])
        pos = end
    magic, width, height = fields[0], int(fields[1]), int(fields[2])
    channels = {b"P6": 3, b"P5": 1}[magic]
    pixels = np.frombuffer(data, dtype=np.uint8, count=width * height * channels, offset=pos + 1)
    return pixels.reshape(height, width, channels) if channels == 3 else pixels.reshape(height, width)


def load_split(folder):
    rgb_files = sorted(glob.glob(os.path.join(folder, "rgb_*.ppm")))
    if not rgb_files:
        raise SystemExit(f"train_segmenter: no rgb_*.ppm in {folder}")
    images = [read_netpbm(f) for f in rgb_files]
    labels = [read_netpbm(f.replace("rgb_", "label_").replace(".ppm", ".pgm")) for f in rgb_files]
    return np.stack(images), np.stack(labels)


def conv_block(c_in, c_out, stride=1, dilation=1):
    # Conv + batch norm + ReLU; the export folds the batch norm into the convolution.
    return nn.Sequential(
        nn.Conv2d(c_in, c_out, 3, stride=stride, padding=dilation, dilation=dilation, bias=False),
        nn.BatchNorm2d(c_out),
        nn.ReLU(inplace=True),
    )


class Segmenter(nn.Module):
    """Two stride-2 stages, then dilated convolutions for context at 1/4 resolution."""

    def __init__(self, classes, width):
        super().__init__()
        self.features = nn.Sequential(
            conv_block(3, width // 2, stride=2),
            conv_block(width // 2, width // 2),
            conv_block(width // 2, width, stride=2),
            conv_block(width, width),
            conv_block(width, width, dilation=2),
            conv_block(width, width, dilation=4),
            conv_block(width, width, dilation=8),
            conv_block(width, width),
        )
        self.classifier = nn.Conv2d(width, classes, 1)

    def forward(self, x):
        return self.classifier(self.features(x))


def confusion(pred, truth, classes):
    keep = truth != 255
    return np.bincount(classes * truth[keep].astype(np.int64) + pred[keep],
                       minlength=classes * classes).reshape(classes, classes)


def iou_per_class(matrix):
    tp = np.diag(matrix).astype(np.float64)
    union = matrix.sum(0) + matrix.sum(1) - tp
    return np.where(union > 0, tp / np.maximum(union, 1), np.nan)


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--data", required=True)
    parser.add_argument("--out", required=True, help="model file (.onnx); the card goes beside it")
    parser.add_argument("--classes", required=True, help="comma-separated model class names")
    parser.add_argument("--epochs", type=int, default=30)
    parser.add_argument("--width", type=int, default=32)
    parser.add_argument("--batch", type=int, default=16)
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--threads", type=int, default=2)
    parser.add_argument("--info", required=True, help="JSON with the render settings for the card")
    args = parser.parse_args()

    torch.manual_seed(args.seed)
    np.random.seed(args.seed)
    torch.set_num_threads(args.threads)
    names = args.classes.split(",")
    classes = len(names)
    info = json.load(open(args.info))

    train_x, train_y = load_split(os.path.join(args.data, "train"))
    val_x, val_y = load_split(os.path.join(args.data, "val"))
    height, width = train_x.shape[1:3]
    mean = train_x.reshape(-1, 3).mean(0) / 255.0
    std = train_x.reshape(-1, 3).std(0) / 255.0

    def tensors(x, y):
        x = (torch.from_numpy(x).float() / 255.0 - torch.tensor(mean).float()) / torch.tensor(std).float()
        return x.permute(0, 3, 1, 2).contiguous(), torch.from_numpy(y).long()

    tx, ty = tensors(train_x, train_y)
    vx, vy = tensors(val_x, val_y)
    # Class weights against the imbalance (road and sky dominate the pixels; poles are rare).
    counts = np.bincount(train_y[train_y != 255].ravel(), minlength=classes).astype(np.float64)
    weights = torch.tensor((counts.sum() / np.maximum(counts, 1)) ** 0.5, dtype=torch.float32)
    weights = weights / weights.mean()

    model = Segmenter(classes, args.width)
    optimiser = torch.optim.Adam(model.parameters(), lr=3e-3)
    schedule = torch.optim.lr_scheduler.CosineAnnealingLR(optimiser, args.epochs)
    started = time.time()
    for epoch in range(args.epochs):
        model.train()
        order = torch.randperm(len(tx))
        total = 0.0
        for i in range(0, len(tx), args.batch):
            batch = order[i:i + args.batch]
            x, y = tx[batch], ty[batch]
            if torch.rand(1).item() < 0.5:  # mirror: the world has no handedness
                x, y = x.flip(3), y.flip(2)
            logits = F.interpolate(model(x), size=(height, width), mode="bilinear",
                                   align_corners=False)
            loss = F.cross_entropy(logits, y, weight=weights, ignore_index=255)
            optimiser.zero_grad()
            loss.backward()
            optimiser.step()
            total += loss.item() * len(batch)
        schedule.step()
        print(f"train_segmenter: epoch {epoch + 1}/{args.epochs} loss {total / len(tx):.4f} "
              f"({time.time() - started:.0f} s)", flush=True)
    train_seconds = time.time() - started

    model.eval()
    matrix = np.zeros((classes, classes), dtype=np.int64)
    with torch.no_grad():
        for i in range(0, len(vx), args.batch):
            logits = F.interpolate(model(vx[i:i + args.batch]), size=(height, width),
                                   mode="bilinear", align_corners=False)
            pred = logits.argmax(1).numpy()
            matrix += confusion(pred.ravel(), val_y[i:i + args.batch].ravel(), classes)
    ious = iou_per_class(matrix)
    print("train_segmenter: validation pixel IoU " +
          ", ".join(f"{n} {v:.3f}" for n, v in zip(names, ious)) + f"; mIoU {np.nanmean(ious):.3f}")

    dummy = torch.zeros(1, 3, height, width)
    torch.onnx.export(model, dummy, args.out, opset_version=11, input_names=["image"],
                      output_names=["logits"], do_constant_folding=True)
    parameters = sum(p.numel() for p in model.parameters())
    write_card(args, info, names, mean, std, width, height, len(tx), len(vx), train_seconds,
               ious, parameters)


def write_card(args, info, names, mean, std, width, height, n_train, n_val, seconds, ious,
               parameters):
    card = os.path.splitext(args.out)[0] + ".yaml"
    lines = [
        "# Model card of semap's shipped segmentation network (written by scripts/train-segmenter;",
        "# do not edit by hand: retrain). DnnSegmenter reads the keys; the comments record how",
        "# the network was made and how well it does.",
        "#",
        f"# Architecture: {len(names)}-class fully convolutional network, two stride-2 stages and",
        f"#   dilated 3x3 convolutions (width {args.width}), logits at 1/4 of the input;",
        f"#   {parameters} parameters, ONNX opset 11.",
        f"# Training set: {n_train} frames of the simulated camera ({info['train_description']}).",
        f"# Validation set: {n_val} frames ({info['val_description']}), never seen in training.",
        f"# Training: {args.epochs} epochs, Adam, cosine schedule, batch {args.batch},",
        f"#   torch seed {args.seed}, CPU with {args.threads} threads, {seconds:.0f} s.",
        "# Validation pixel IoU per class:",
    ]
    for name, iou in zip(names, ious):
        lines.append(f"#   {name:<11} {iou:.3f}")
    lines += [
        f"#   mean        {np.nanmean(ious):.3f}",
        "",
        f"model: {os.path.basename(args.out)}",
        "input:",
        f"  width: {width}",
        f"  height: {height}",
        "  channel_order: rgb",
        "  mean: [" + ", ".join(f"{m:.4f}" for m in mean) + "]",
        "  std: [" + ", ".join(f"{s:.4f}" for s in std) + "]",
        "output: logits",
        "threads: 2",
        "model_classes:",
        "  names: [" + ", ".join(names) + "]",
        "  colors: [" + ",   ".join(", ".join(str(c) for c in info["colors"][n]) for n in names)
        + "]",
        "map:",
        f"  num_classes: {info['map_classes']}",
        "  from_model:",
    ]
    for name in names:
        target = info["map_class"][name]
        lines.append(f"    {name}: {target}")
    lines.append("  unmapped: drop")
    with open(card, "w") as f:
        f.write("\n".join(lines) + "\n")
    print(f"train_segmenter: wrote {args.out} and {card}")


if __name__ == "__main__":
    main()
