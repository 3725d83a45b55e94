"""Recovers a train.py network's weights from its exported ONNX file, so a run whose checkpoints are gone (another
machine, a clean clone: only the export is committed) can be continued (train.py --init) or joined to an ensemble
(ensemble.py).

The export folds every batch normalisation into the convolution before it and renames the folded tensors
("onnx::Conv_615"), so the file's initializers cannot be matched to the network's parameters by name or by value.
They are matched by position instead: a copy of the network with the same architecture is exported the same way,
its every parameter element holding its own global index (1, 2, 3 ... as floats, exact below 2^24) and its batch
normalisations set to the identity (gamma 1, beta indexed, mean 0, variance 1 - eps). The exporter then writes
initializers whose elements name the parameter elements they came from, through whatever transposes, reshapes and
foldings it applied; the two graphs have the same nodes in the same order, so the file's initializer at the same
place holds the values. A folded batch normalisation comes back as the identity with the folded bias as its beta:
the network computes in evaluation mode exactly what the file computes. Training mode normalises with batch
statistics instead, so calibrate_batch_norm() then sets each batch normalisation's statistics to those of its
inputs (and gamma, beta to match), which leaves the evaluation-mode function unchanged and makes the training-mode
one start where the exported network is.

An ensemble.py export is read the same way: its int8 convolutions are first turned back into float ones (the weights
as rounded; quantize.py), its members' networks form the probe, and recover_members() splits the recovered state
into the members' own. The members then compute what they computed inside the ensemble file.
"""
import copy
import io

import numpy as np
import torch
import torch.nn as nn

from .export import export_onnx
from .model import Ensemble
from .quantize import dequantize_conv_weights

_EXACT = 1 << 24  # float32 holds every integer up to 2^24 exactly


def _is_batch_norm(module):
    return isinstance(module, nn.modules.batchnorm._BatchNorm)


def _make_identity(bn):
    """gamma 1, mean 0 and a variance with var + eps == 1 in float32: the normalisation multiplies by exactly 1."""
    bn.weight.fill_(1.0)
    bn.running_mean.zero_()
    var = np.float32(1.0) - np.float32(bn.eps)
    while np.float32(var + np.float32(bn.eps)) != np.float32(1.0):
        var = np.nextafter(var, np.float32(2.0) if var + np.float32(bn.eps) < 1 else np.float32(0.0))
    bn.running_var.fill_(float(var))


def _export(model, inputs, size):
    buffer = io.BytesIO()
    export_onnx(model, inputs, size, buffer)  # the probe is exported exactly as the run was
    import onnx  # python3-onnx
    return onnx.load_from_string(buffer.getvalue())


def inline_identity_constants(model):
    """Replaces, in `model` (an onnx.ModelProto), each Identity node that copies an initializer by a copy of that
    initializer named as its output. The exporter writes such nodes for tensors that appear twice with the same
    values (an ensemble's members' fixed input conversion); ensemble.py removes them because OpenCV 4.6 cannot parse
    them, and the probe gets the same treatment so that both graphs keep the same nodes. Returns the number removed."""
    graph = model.graph
    constants = {t.name: t for t in graph.initializer}
    identities = [n for n in graph.node if n.op_type == "Identity" and n.input[0] in constants]
    for node in identities:
        tensor = copy.deepcopy(constants[node.input[0]])
        tensor.name = node.output[0]
        graph.initializer.append(tensor)
        graph.node.remove(node)
    return len(identities)


def _initializers(graph):
    from onnx import numpy_helper
    return {t.name: numpy_helper.to_array(t) for t in graph.initializer}


def recover_state(model, onnx_path, inputs, size):
    """The state dict of `model` (a train.py UNet or ContextUNet, built with the settings of the run that exported
    `onnx_path` at `inputs` channels and `size` pixels) that computes, in evaluation mode, what the file computes.
    `model` may be ensemble.py's Ensemble of the members' networks, for an ensemble's export (see recover_members).
    Int8 weights (quantize.py) come back as rounded. ValueError says what does not fit: another architecture, an
    ensemble read as one network or one network as an ensemble."""
    import onnx  # python3-onnx
    try:
        exported = onnx.load(onnx_path)
    except Exception as e:  # onnx raises its own DecodeError and OSError subclasses
        raise ValueError(f"{onnx_path}: not an ONNX file ({e})") from e
    dequantize_conv_weights(exported)
    inline_identity_constants(exported)
    template = copy.deepcopy(model).cpu().eval()
    bns = {name for name, m in template.named_modules() if _is_batch_norm(m)}
    gammas = {f"{name}.weight" for name in bns}
    names, starts = [], []
    with torch.no_grad():
        for name in bns:
            _make_identity(template.get_submodule(name))
        next_index = 1  # 0 stays free: exported zeros (paddings, constants) name nothing
        for name, p in template.named_parameters():
            if name in gammas:
                continue
            names.append(name)
            starts.append(next_index)
            p.copy_(torch.arange(next_index, next_index + p.numel(), dtype=torch.float64).view_as(p))
            next_index += p.numel()
    if next_index >= _EXACT:
        raise ValueError(f"the network has {next_index - 1} weights; positions are exact in float32 only below {_EXACT}")
    probe = _export(template, inputs, size)
    inline_identity_constants(probe)

    ops = [n.op_type for n in exported.graph.node]
    if ops != [n.op_type for n in probe.graph.node]:
        raise ValueError(f"{onnx_path}: not this network's export ({len(ops)} nodes against "
                         f"{len(probe.graph.node)}): other settings, or an ensemble read as one network?")
    values, positions = _initializers(exported.graph), _initializers(probe.graph)
    params = dict(template.named_parameters())
    state = {name: torch.full_like(params[name], float("nan")) for name in names}
    for node, probe_node in zip(exported.graph.node, probe.graph.node):
        for name, probe_name in zip(node.input, probe_node.input):
            if probe_name not in positions:
                continue
            where, value = positions[probe_name], values.get(name)
            if value is not None and (where.dtype.kind != "f" or np.array_equal(where, value)):
                continue  # a constant of the graph (shapes, scales), the same in both: no weight
            if value is None or value.shape != where.shape:
                raise ValueError(f"{onnx_path}: not this network's export (node {node.name or node.op_type} has no "
                                 f"initializer shaped {list(where.shape)} where this network's has one): other "
                                 f"settings?")
            index = np.rint(where.astype(np.float64)).astype(np.int64).ravel()
            if np.abs(where.ravel() - index).max(initial=0) > 1e-3 or index.min(initial=1) < 0 or \
                    index.max(initial=0) >= next_index:
                raise ValueError(f"{onnx_path}: initializer {name} combines several weights (an operation that "
                                 f"cannot be undone)")
            value = value.astype(np.float32).ravel()
            weights = index > 0
            index, value = index[weights], value[weights]
            owner = np.searchsorted(starts, index, side="right") - 1
            for k in np.unique(owner):
                mine = owner == k
                flat = state[names[k]].view(-1)
                flat[torch.from_numpy(index[mine] - starts[k])] = torch.from_numpy(value[mine])
    missing = [name for name in names if torch.isnan(state[name]).any()]
    if missing:
        raise ValueError(f"{onnx_path}: holds no values for {missing[:3]} ({len(missing)} parameters)")
    whole = template.state_dict()
    whole.update(state)
    return whole


def combine_of(onnx_path):
    """How the ensemble.py export `onnx_path` averages its members (a model.COMBINES key): older exports
    average log-softmax, which leaves LogSoftmax nodes in the graph. An unreadable file reads as "logits" here;
    recover_state then names what is wrong with it."""
    import onnx  # python3-onnx
    try:
        graph = onnx.load(onnx_path).graph
    except Exception:  # onnx raises its own DecodeError and OSError subclasses
        return "logits"
    return "log_softmax" if any(n.op_type == "LogSoftmax" for n in graph.node) else "logits"


def recover_members(members, onnx_path, inputs, size):
    """The state dicts of the members of an ensemble.py export `onnx_path`, `members` being networks built with the
    members' settings in the ensemble's order (their weights do not matter). Each computes, in evaluation mode, what
    it computes inside the file: its logit adjustment folded in, its int8 weights as rounded. Both of ensemble.py's
    combines are read: the probe averages as the file does (log-softmax in exports before 2026-11-24)."""
    state = recover_state(Ensemble(members, combine_of(onnx_path)), onnx_path, inputs, size)
    states = []
    for k in range(len(members)):
        prefix = f"members.{k}."
        states.append({name[len(prefix):]: value for name, value in state.items() if name.startswith(prefix)})
    return states


def calibrate_batch_norm(model, batches):
    """Sets every batch normalisation of `model` (recovered as the identity plus a bias by recover_state) to the
    statistics of its inputs over `batches` (input tensors), with gamma and beta such that evaluation mode computes
    what it computed before. Returns the number of batch normalisations calibrated."""
    bns = [m for m in model.modules() if _is_batch_norm(m)]
    sums = {id(m): [0.0, 0.0, 0] for m in bns}

    def record(module, args, _):
        x = args[0].detach().double().transpose(0, 1).reshape(args[0].shape[1], -1)
        s = sums[id(module)]
        s[0] = s[0] + x.sum(1)
        s[1] = s[1] + (x * x).sum(1)
        s[2] += x.shape[1]

    hooks = [m.register_forward_hook(record) for m in bns]
    was_training = model.training
    model.eval()
    try:
        with torch.no_grad():
            for x in batches:
                model(x)
    finally:
        for h in hooks:
            h.remove()
        model.train(was_training)
    with torch.no_grad():
        for m in bns:
            total, squares, n = sums[id(m)]
            if n == 0:
                continue
            mean = total / n
            var = (squares / n - mean * mean).clamp(min=0)
            # Before: y = gamma (x - mu) / sqrt(v + eps) + beta. After: the same y with mu, v the inputs' statistics.
            scale = m.weight.double() / torch.sqrt(m.running_var.double() + m.eps)
            shift = m.bias.double() - scale * m.running_mean.double()
            std = torch.sqrt(var + m.eps)
            m.running_mean.copy_(mean)
            m.running_var.copy_(var)
            m.weight.copy_(scale * std)
            m.bias.copy_(shift + scale * mean)
    return sum(1 for m in bns if sums[id(m)][2] > 0)
