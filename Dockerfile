# svrc-server and the svrc CLI on Debian bookworm. Multi-stage: the build
# stage installs the build packages with scripts/setup.sh (the same script
# the README and CI use) and builds the two binaries; the runtime stage
# installs only the runtime libraries (scripts/setup.sh --runtime) and runs as
# a non-root user. The health check is the CLI itself (`svrc health`, which
# runs svrc-remote: the `svrc` binary holds the local commands only).
FROM debian:bookworm AS build
WORKDIR /src
COPY scripts/setup.sh scripts/setup.sh
RUN bash scripts/setup.sh && rm -rf /var/lib/apt/lists/*
COPY . .
RUN cmake -S . -B build/release -G Ninja -DCMAKE_BUILD_TYPE=Release -DSVRC_BUILD_TESTS=OFF \
 && cmake --build build/release -j "$(nproc)" --target svrc svrc-remote svrc-server \
 && install -D build/release/server/svrc-server /out/usr/local/bin/svrc-server \
 && install -D build/release/client/svrc /out/usr/local/bin/svrc \
 && install -D build/release/client/svrc-remote /out/usr/local/bin/svrc-remote

FROM debian:bookworm AS runtime
COPY scripts/setup.sh /tmp/setup.sh
RUN bash /tmp/setup.sh --runtime && rm -rf /var/lib/apt/lists/* /tmp/setup.sh \
 && useradd --system --uid 10001 --home-dir /var/lib/svrc --create-home svrc
COPY --from=build /out/ /
USER svrc
VOLUME ["/var/lib/svrc"]
EXPOSE 50051
# Workers, queue and retention are flags; override CMD to change them
# (deploy/docker-compose.yml does).
CMD ["svrc-server", "--listen=0.0.0.0:50051", "--workers=2", "--queue-capacity=64", \
     "--data-dir=/var/lib/svrc"]
HEALTHCHECK --interval=15s --timeout=5s --start-period=10s --retries=3 \
  CMD ["svrc", "health", "--server", "127.0.0.1:50051"]
