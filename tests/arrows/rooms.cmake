# The rooms and their arrows (docs/ARCHITECTURE.md), as room_arrows.cmake checks them. For each
# room: its library, one of its public headers, one of its internal headers ("" when all are
# public) and the rooms whose public headers it sees. A room sees a room it links, and through
# that room's public headers the rooms they include (host's name protocol's, frames' and
# render's types). Headers are paths from the source root; the probes include them by bare name.
set(SKYD_ROOMS protocol base world frames cluster forecast host net cli render)

set(SKYD_ROOM_protocol_TARGET skyd_protocol)
set(SKYD_ROOM_protocol_PUBLIC protocol/include/world_state.h)
set(SKYD_ROOM_protocol_INTERNAL protocol/world_fields.h)
set(SKYD_ROOM_protocol_SEES "")

set(SKYD_ROOM_base_TARGET skyd_server_base)
set(SKYD_ROOM_base_PUBLIC server/base/include/log.h)
set(SKYD_ROOM_base_INTERNAL "")
set(SKYD_ROOM_base_SEES "")

set(SKYD_ROOM_world_TARGET skyd_world)
set(SKYD_ROOM_world_PUBLIC server/world/include/world_sim.h)
set(SKYD_ROOM_world_INTERNAL server/world/ephemeris_internal.h)
set(SKYD_ROOM_world_SEES protocol base)

set(SKYD_ROOM_frames_TARGET skyd_frames)
set(SKYD_ROOM_frames_PUBLIC server/frames/include/session.h)
set(SKYD_ROOM_frames_INTERNAL "")
set(SKYD_ROOM_frames_SEES protocol base)

set(SKYD_ROOM_cluster_TARGET skyd_cluster)
set(SKYD_ROOM_cluster_PUBLIC server/cluster/include/cluster_store.h)
set(SKYD_ROOM_cluster_INTERNAL server/cluster/cluster_redis.h)
set(SKYD_ROOM_cluster_SEES base)

set(SKYD_ROOM_forecast_TARGET skyd_forecast)
set(SKYD_ROOM_forecast_PUBLIC server/forecast/include/forecast.h)
set(SKYD_ROOM_forecast_INTERNAL server/forecast/forecast_grid.h)
set(SKYD_ROOM_forecast_SEES protocol base)

set(SKYD_ROOM_host_TARGET skyd_host)
set(SKYD_ROOM_host_PUBLIC server/host/include/render_loop.h)
set(SKYD_ROOM_host_INTERNAL server/host/state_store.h)
set(SKYD_ROOM_host_SEES protocol base world frames cluster forecast render)

set(SKYD_ROOM_net_TARGET skyd_net)
set(SKYD_ROOM_net_PUBLIC server/net/include/ws_server.h)
set(SKYD_ROOM_net_INTERNAL server/net/http_api.h)
set(SKYD_ROOM_net_SEES protocol base frames host render)

set(SKYD_ROOM_cli_TARGET skyd_cli)
set(SKYD_ROOM_cli_PUBLIC server/cli/include/commands.h)
set(SKYD_ROOM_cli_INTERNAL server/cli/cli_args.h)
set(SKYD_ROOM_cli_SEES protocol base world frames forecast host net render)

set(SKYD_ROOM_render_TARGET skyd_render)
set(SKYD_ROOM_render_PUBLIC render/include/sky_renderer.h)
set(SKYD_ROOM_render_INTERNAL render/vk/vk_context.h)
set(SKYD_ROOM_render_SEES "")
