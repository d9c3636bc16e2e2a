#!/usr/bin/env python3
"""The Open Inference Protocol's gRPC service driven by a client this project did not write.

Python's grpcio (Debian's python3-grpcio) with stubs compiled here from
proto/inference/grpc_service.proto by Debian's protoc and grpc_python_plugin, against a real
tod_server on the fixture's model (port 0, reported through --ports-file): every method, the
binary contents in both directions, the uint8 map, the protocol's errors and the bearer token.
Exits non-zero with the first failed check.

usage: oip_grpc_client_test.py --server BIN --model DIR --frames DIR --proto-dir DIR --work DIR
(the first PNG under --frames is the frame)
"""
import argparse
import json
import os
import pathlib
import re
import shutil
import signal
import struct
import subprocess
import sys
import time
import urllib.request


def compile_stubs(proto_dir, out_dir):
    out_dir.mkdir(parents=True, exist_ok=True)
    plugin = shutil.which("grpc_python_plugin") or "/usr/bin/grpc_python_plugin"
    subprocess.run(["protoc", f"--proto_path={proto_dir}", f"--python_out={out_dir}",
                    f"--grpc_out={out_dir}", f"--plugin=protoc-gen-grpc={plugin}",
                    str(proto_dir / "inference" / "grpc_service.proto")], check=True)
    sys.path.insert(0, str(out_dir))


def start_server(args, work, token_file):
    ports_file = work / "ports.json"
    ports_file.unlink(missing_ok=True)
    log = open(work / "server.log", "w")
    command = [args.server, "--model", args.model, "--grpc-port", "0", "--http-port", "0",
               "--host", "127.0.0.1", "--ports-file", str(ports_file), "--workers", "1"]
    if token_file:
        command += ["--auth-token-file", str(token_file)]
    process = subprocess.Popen(command, stdout=log, stderr=subprocess.STDOUT)
    deadline = time.monotonic() + 120
    while not ports_file.exists():
        if process.poll() is not None or time.monotonic() > deadline:
            process.kill()
            sys.exit(f"tod_server did not start; see {work / 'server.log'}")
        time.sleep(0.05)
    ports = json.loads(ports_file.read_text())
    return process, ports["grpc"], ports["http"]


def stop_server(process):
    process.send_signal(signal.SIGTERM)
    try:
        process.wait(timeout=60)
    except subprocess.TimeoutExpired:
        process.kill()
        sys.exit("tod_server did not stop on SIGTERM")


def check(condition, what):
    if not condition:
        sys.exit("FAILED: " + what)
    print("ok:", what)


def bytes_element(data):
    return struct.pack("<I", len(data)) + data


def wait_ready(stub, pb, metadata=()):
    deadline = time.monotonic() + 120
    while time.monotonic() < deadline:
        if stub.ServerReady(pb.ServerReadyRequest(), metadata=metadata, timeout=10).ready:
            return
        time.sleep(0.05)
    sys.exit("the server never became ready")


def expect_error(grpc, call, code, part, what):
    try:
        call()
    except grpc.RpcError as error:
        check(error.code() == code and part in error.details(),
              f"{what}: {code.name} with '{part}' (got {error.code().name}: {error.details()})")
        return
    sys.exit(f"FAILED: {what}: the call succeeded")


def infer_request(pb, image, model, parameters=None, outputs=()):
    request = pb.ModelInferRequest(model_name=model, id="req-1")
    tensor = request.inputs.add()
    tensor.name, tensor.datatype = "image", "BYTES"
    tensor.shape.append(1)
    request.raw_input_contents.append(bytes_element(image))
    for name, value in (parameters or {}).items():
        if isinstance(value, str):
            request.parameters[name].string_param = value
        else:
            request.parameters[name].int64_param = value
    for name in outputs:
        request.outputs.add().name = name
    return request


def check_open_server(grpc, pb, stub, image, model):
    wait_ready(stub, pb)
    check(stub.ServerLive(pb.ServerLiveRequest()).live, "ServerLive says live")
    server = stub.ServerMetadata(pb.ServerMetadataRequest())
    check(server.name == "tod" and "binary_tensor_data" in server.extensions,
          "ServerMetadata names tod and its extension")
    metadata = stub.ModelMetadata(pb.ModelMetadataRequest(name=model))
    check([t.name for t in metadata.inputs] == ["image"] and metadata.inputs[0].datatype == "BYTES",
          "ModelMetadata: one BYTES input 'image'")
    check([t.name for t in metadata.outputs] == ["obstacles", "proposals", "probability_map"],
          "ModelMetadata: the three outputs")
    check(list(metadata.outputs[1].shape) == [-1, 7], "proposals are FP32 [-1, 7]")
    check(stub.ModelReady(pb.ModelReadyRequest(name=model)).ready, "ModelReady says ready")
    version = metadata.versions[0]
    check(stub.ModelReady(pb.ModelReadyRequest(name=model, version=version)).ready,
          "ModelReady with the model's version")
    expect_error(grpc, lambda: stub.ModelReady(pb.ModelReadyRequest(name="nope")),
                 grpc.StatusCode.NOT_FOUND, "unknown model", "ModelReady of another model")
    expect_error(grpc, lambda: stub.ModelMetadata(pb.ModelMetadataRequest(name=model, version="x9")),
                 grpc.StatusCode.NOT_FOUND, "no version", "ModelMetadata of another version")

    response = stub.ModelInfer(infer_request(pb, image, model, {"max_proposals": 5}), timeout=120)
    check(response.model_name == model and response.id == "req-1", "ModelInfer echoes model and id")
    names = [o.name for o in response.outputs]
    check(names == ["obstacles", "proposals", "probability_map"], "ModelInfer returns every output")
    check(len(response.raw_output_contents) == 3, "outputs come in raw_output_contents")
    proposals = response.outputs[1]
    rows, columns = proposals.shape
    check(proposals.datatype == "FP32" and columns == 7 and 0 < rows <= 5,
          f"proposals FP32 [{rows}, 7], at most max_proposals")
    check(len(response.raw_output_contents[1]) == rows * columns * 4, "proposal bytes match shape")
    values = struct.unpack(f"<{rows * columns}f", response.raw_output_contents[1])
    check(all(values[i * 7 + 2] > 0 and values[i * 7 + 3] > 0 for i in range(rows)),
          "proposal boxes have a size")
    check(proposals.parameters["columns"].string_param == "x,y,w,h,fused,ordr,obdr",
          "proposals carry their columns")
    raw_map = response.raw_output_contents[2]
    (length,) = struct.unpack("<I", raw_map[:4])
    check(length == len(raw_map) - 4 and raw_map[4:12] == b"\x89PNG\r\n\x1a\n",
          "the map is one length-prefixed PNG")
    width = response.parameters["width"].int64_param
    height = response.parameters["height"].int64_param

    uint8 = stub.ModelInfer(infer_request(pb, image, model, {"map_format": "uint8"},
                                          ["probability_map"]), timeout=120)
    check([o.name for o in uint8.outputs] == ["probability_map"], "only the output asked for")
    check(uint8.outputs[0].datatype == "UINT8" and list(uint8.outputs[0].shape) == [height, width],
          f"map_format uint8: UINT8 [{height}, {width}]")
    check(len(uint8.raw_output_contents[0]) == width * height, "the uint8 map has H x W bytes")

    typed = infer_request(pb, image, model)
    del typed.raw_input_contents[:]
    typed.inputs[0].contents.bytes_contents.append(image)
    check(len(stub.ModelInfer(typed, timeout=120).outputs) == 3, "the image in bytes_contents")

    expect_error(grpc, lambda: stub.ModelInfer(infer_request(pb, image, "nope")),
                 grpc.StatusCode.NOT_FOUND, "unknown model", "ModelInfer of another model")
    expect_error(grpc, lambda: stub.ModelInfer(infer_request(pb, b"not an image", model)),
                 grpc.StatusCode.INVALID_ARGUMENT, "", "ModelInfer of bytes that are no image")
    bad = infer_request(pb, image, model)
    bad.raw_input_contents[0] = image  # no length prefix
    expect_error(grpc, lambda: stub.ModelInfer(bad), grpc.StatusCode.INVALID_ARGUMENT, "declares",
                 "raw contents without the BYTES length")
    expect_error(grpc, lambda: stub.ModelInfer(infer_request(pb, image, model,
                                                             {"max_proposals": -1})),
                 grpc.StatusCode.INVALID_ARGUMENT, "parameter max_proposals",
                 "an option out of range names the parameter")
    expect_error(grpc, lambda: stub.ModelInfer(infer_request(pb, image, model, outputs=["x"])),
                 grpc.StatusCode.INVALID_ARGUMENT, "no output 'x'", "an unknown output")
    expect_error(grpc, lambda: stub.ModelInfer(infer_request(pb, image, model, {"timeout_ms": 1}),
                                               timeout=120),
                 grpc.StatusCode.DEADLINE_EXCEEDED, "deadline", "timeout_ms passed in the server")


def check_metrics(http_port):
    """The protocol's calls are counted like tod.v1's: three answered frames, the refusals."""
    text = urllib.request.urlopen(f"http://127.0.0.1:{http_port}/metrics", timeout=30).read()
    counts = {}
    for line in text.decode().splitlines():
        match = re.match(r'tod_requests_total\{(.*)\} (\S+)', line)
        if match and 'protocol="grpc"' in match.group(1):
            code = re.search(r'code="([A-Z_]+)"', match.group(1)).group(1)
            counts[code] = counts.get(code, 0) + float(match.group(2))
    check(counts.get("OK", 0) >= 3 + 1, f"tod_requests_total counts the answered infers: {counts}")
    check(counts.get("INVALID_ARGUMENT", 0) >= 4, "and the refused ones")
    check(counts.get("DEADLINE_EXCEEDED", 0) >= 1, "and the one past its deadline")


def check_token(grpc, pb, stub, image, model, token):
    good = (("authorization", "Bearer " + token),)
    wait_ready(stub, pb)  # open, like the health service
    check(stub.ServerLive(pb.ServerLiveRequest()).live, "ServerLive needs no token")
    for what, call in [
            ("ServerMetadata", lambda m: stub.ServerMetadata(pb.ServerMetadataRequest(), metadata=m)),
            ("ModelReady", lambda m: stub.ModelReady(pb.ModelReadyRequest(name=model), metadata=m)),
            ("ModelInfer", lambda m: stub.ModelInfer(infer_request(pb, image, model), metadata=m,
                                                     timeout=120))]:
        expect_error(grpc, lambda: call(()), grpc.StatusCode.UNAUTHENTICATED, "",
                     f"{what} without a token")
        expect_error(grpc, lambda: call((("authorization", "Bearer wrong-token-wrong-token"),)),
                     grpc.StatusCode.UNAUTHENTICATED, "", f"{what} with a wrong token")
        call(good)
        print(f"ok: {what} with the token")


def main():
    parser = argparse.ArgumentParser()
    for name in ["server", "model", "frames", "proto-dir", "work"]:
        parser.add_argument("--" + name, required=True)
    args = parser.parse_args()
    work = pathlib.Path(args.work)
    shutil.rmtree(work, ignore_errors=True)
    work.mkdir(parents=True)
    compile_stubs(pathlib.Path(args.proto_dir), work / "stubs")
    import grpc
    from inference import grpc_service_pb2 as pb
    from inference import grpc_service_pb2_grpc as rpc
    image = sorted(pathlib.Path(args.frames).rglob("*.png"))[0].read_bytes()
    model = pathlib.Path(args.model).resolve().name

    process, port, http_port = start_server(args, work, None)
    try:
        with grpc.insecure_channel(f"127.0.0.1:{port}") as channel:
            check_open_server(grpc, pb, rpc.GRPCInferenceServiceStub(channel), image, model)
        check_metrics(http_port)
    finally:
        stop_server(process)

    token = "oip-test-token-0123456789abcdef"
    token_file = work / "tokens"
    token_file.write_text(token + "\n")
    process, port, _ = start_server(args, work, token_file)
    try:
        with grpc.insecure_channel(f"127.0.0.1:{port}") as channel:
            check_token(grpc, pb, rpc.GRPCInferenceServiceStub(channel), image, model, token)
    finally:
        stop_server(process)
    print("all checks passed")


if __name__ == "__main__":
    main()
