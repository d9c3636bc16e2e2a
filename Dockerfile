# tod-server image. Build: docker build -t tod-server:0.1.0 .
# Run:   docker run --rm -p 8001:8001 -p 8000:8000 tod-server:0.1.0
# Packages come only from deploy/deps.sh (the one list); the build stage compiles and runs the
# whole test suite, the runtime stage carries only runtime libraries, the binaries and models/.

FROM debian:12-slim AS build
WORKDIR /src
COPY deploy/deps.sh deploy/deps.sh
RUN bash deploy/deps.sh build && rm -rf /var/lib/apt/lists/*
COPY . .
RUN cmake -S . -B /build -G Ninja -DTOD_BUILD_SERVICE=ON \
 && ninja -C /build \
 && ctest --test-dir /build --output-on-failure -j2 \
 && install -d /out/bin \
 && install -m 0755 /build/bin/tod_server /build/bin/tod_client /build/bin/tod_load /build/bin/tod \
      /out/bin/

FROM debian:12-slim AS runtime
COPY deploy/deps.sh /tmp/deps.sh
RUN bash /tmp/deps.sh runtime && rm -rf /var/lib/apt/lists/* /tmp/deps.sh \
 && groupadd --system --gid 10001 tod \
 && useradd --system --uid 10001 --gid tod --home-dir /opt/tod --no-create-home \
      --shell /usr/sbin/nologin tod
COPY --from=build /out/bin/ /opt/tod/bin/
COPY models/ /opt/tod/models/
ENV PATH=/opt/tod/bin:$PATH \
    TOD_LOG_FORMAT=json
USER 10001:10001
WORKDIR /opt/tod
# gRPC, REST (+ /metrics)
EXPOSE 8001 8000
HEALTHCHECK --interval=15s --timeout=5s --start-period=120s --retries=3 \
  CMD ["/opt/tod/bin/tod_client", "health", "--addr", "127.0.0.1:8001"]
# tini reaps children and forwards SIGTERM/SIGHUP to the server (drain / reload).
ENTRYPOINT ["/usr/bin/tini", "--"]
CMD ["/opt/tod/bin/tod_server", "--model", "/opt/tod/models/default", "--grpc-port", "8001", "--http-port", "8000"]
