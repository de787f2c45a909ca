//! The renderer: one per body and colour format. `prepare` brings the device copies of the
//! body up to date and deforms the skin (compute); `render` draws one pass per view into
//! the caller's target views (4× MSAA resolved into them).

use glam::{Mat4, Vec3};
use incise_sim::TetMesh;
use incise_sim::skin::Skin;
use wgpu::util::DeviceExt;

use crate::camera::View;
use crate::error::RenderError;
use crate::frame::{BodyState, RenderSettings, ShadingMode};
use crate::gpu_skin::GpuSkin;
use crate::panel::Panel;
use crate::pipelines::Pipelines;
use crate::scene_buffers::{GLOBALS_STRIDE, Globals, MAX_VIEWS, SceneBuffers};
use crate::targets::Attachments;
use crate::tool_mesh::ToolMesh;

/// Key light: from above, front left of the default view.
const LIGHT_DIR: Vec3 = Vec3::new(0.35, -0.55, 0.76);
const LIGHT_INTENSITY: f32 = 3.2;

/// A mesh on the device: interleaved position + normal, and indices.
struct MeshBuffers {
    vertices: wgpu::Buffer,
    indices: wgpu::Buffer,
    index_count: u32,
}

impl MeshBuffers {
    fn new(device: &wgpu::Device, mesh: &ToolMesh) -> Self {
        let vertices: Vec<[f32; 6]> = mesh
            .positions
            .iter()
            .zip(&mesh.normals)
            .map(|(p, n)| [p.x, p.y, p.z, n.x, n.y, n.z])
            .collect();
        MeshBuffers {
            vertices: device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("tool vertices"),
                contents: bytemuck::cast_slice(&vertices),
                usage: wgpu::BufferUsages::VERTEX,
            }),
            indices: device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("tool indices"),
                contents: bytemuck::cast_slice(&mesh.indices),
                usage: wgpu::BufferUsages::INDEX,
            }),
            index_count: mesh.indices.len() as u32 * 3,
        }
    }

    /// Positions only (stride 12), for the marker sphere.
    fn positions_only(device: &wgpu::Device, mesh: &ToolMesh) -> Self {
        let vertices: Vec<[f32; 3]> = mesh.positions.iter().map(|p| p.to_array()).collect();
        MeshBuffers {
            vertices: device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("sphere vertices"),
                contents: bytemuck::cast_slice(&vertices),
                usage: wgpu::BufferUsages::VERTEX,
            }),
            indices: device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("sphere indices"),
                contents: bytemuck::cast_slice(&mesh.indices),
                usage: wgpu::BufferUsages::INDEX,
            }),
            index_count: mesh.indices.len() as u32 * 3,
        }
    }
}

/// GPU timestamps around a frame's passes (when the adapter has them).
struct Timer {
    queries: wgpu::QuerySet,
    resolve: wgpu::Buffer,
    read: wgpu::Buffer,
    period_ns: f32,
}

/// Draws one body (tet mesh + skin) with its cut surface, overlays, tool, surface lines
/// and panel quad.
pub struct Renderer {
    device: wgpu::Device,
    queue: wgpu::Queue,
    format: wgpu::TextureFormat,
    pipelines: Pipelines,
    scene: SceneBuffers,
    skin: GpuSkin,
    tool: MeshBuffers,
    sphere: MeshBuffers,
    panel: Panel,
    attachments: Option<Attachments>,
    settings: RenderSettings,
    timer: Option<Timer>,
}

impl Renderer {
    /// A renderer for `mesh` and its `skin`, drawing into targets of `format` (an sRGB
    /// format gives sRGB output).
    pub fn new(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        format: wgpu::TextureFormat,
        mesh: &TetMesh,
        skin: &Skin,
    ) -> Self {
        let scene = SceneBuffers::new(device, mesh, skin);
        let skin_gpu = GpuSkin::new(device, skin, &scene.nodes);
        let panel = Panel::new(device);
        Renderer {
            pipelines: Pipelines::new(device, &scene.layout, &panel.layout, format),
            panel,
            tool: MeshBuffers::new(device, &ToolMesh::scalpel()),
            sphere: MeshBuffers::positions_only(device, &ToolMesh::unit_sphere(2)),
            skin: skin_gpu,
            scene,
            device: device.clone(),
            queue: queue.clone(),
            format,
            attachments: None,
            settings: RenderSettings::default(),
            timer: None,
        }
    }

    /// Draw `mesh` (tool frame, placed by [`crate::frame::ToolState::transform`]) as the
    /// tool from now on, instead of the stand-in blade.
    pub fn set_tool_mesh(&mut self, mesh: &ToolMesh) {
        self.tool = MeshBuffers::new(&self.device, mesh);
    }

    /// Upload the image shown on the panel quad (RGBA8, sRGB, row-major, top row first);
    /// `None` removes it. The quad is drawn where [`RenderSettings::panel`] places it,
    /// only while an image is set.
    ///
    /// # Errors
    /// [`RenderError::PanelImage`] when the byte count is not width · height · 4, a side
    /// is zero, or a side exceeds the device's largest 2D texture; the panel then keeps
    /// its previous image.
    pub fn set_panel_image(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        image: Option<(&[u8], u32, u32)>,
    ) -> Result<(), RenderError> {
        self.panel.set(device, queue, image)
    }

    /// The colour format this renderer draws.
    pub fn format(&self) -> wgpu::TextureFormat {
        self.format
    }

    /// Take GPU timestamps around each frame from now on, if the device supports them;
    /// returns whether it does. Read them with [`Renderer::last_gpu_ms`].
    pub fn enable_gpu_timing(&mut self) -> bool {
        if !self
            .device
            .features()
            .contains(wgpu::Features::TIMESTAMP_QUERY)
        {
            return false;
        }
        let buffer = |label, usage| {
            self.device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size: 16,
                usage,
                mapped_at_creation: false,
            })
        };
        self.timer = Some(Timer {
            queries: self.device.create_query_set(&wgpu::QuerySetDescriptor {
                label: Some("frame timestamps"),
                ty: wgpu::QueryType::Timestamp,
                count: 2,
            }),
            resolve: buffer(
                "timestamp resolve",
                wgpu::BufferUsages::QUERY_RESOLVE | wgpu::BufferUsages::COPY_SRC,
            ),
            read: buffer(
                "timestamp read",
                wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            ),
            period_ns: self.queue.get_timestamp_period(),
        });
        true
    }

    /// Update the body's device data from `state` and record the skin deformation.
    pub fn prepare(
        &mut self,
        encoder: &mut wgpu::CommandEncoder,
        state: &BodyState<'_>,
        settings: &RenderSettings,
    ) {
        self.settings = settings.clone();
        self.scene
            .update(&self.device, &self.queue, encoder, state, settings);
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("skin"),
            timestamp_writes: self
                .timer
                .as_ref()
                .map(|t| wgpu::ComputePassTimestampWrites {
                    query_set: &t.queries,
                    beginning_of_pass_write_index: Some(0),
                    end_of_pass_write_index: None,
                }),
        });
        self.skin.record(&mut pass);
    }

    /// Draw the prepared frame once per view into `targets` (each view paired with a
    /// single-layer, single-sample view of a `size` texture in this renderer's format).
    ///
    /// # Panics
    /// With more than 4 views.
    pub fn render(
        &mut self,
        encoder: &mut wgpu::CommandEncoder,
        views: &[(View, &wgpu::TextureView)],
        size: (u32, u32),
    ) {
        assert!(views.len() as u64 <= MAX_VIEWS, "at most {MAX_VIEWS} views");
        if self.attachments.as_ref().is_none_or(|a| a.size != size) {
            self.attachments = Some(Attachments::new(&self.device, self.format, size));
        }
        let s = &self.settings;
        let ids = s.shading == ShadingMode::MaterialIds;
        let tool_model = s.tool.transform.unwrap_or(Mat4::IDENTITY);
        let panel_model = s.panel.unwrap_or(Mat4::IDENTITY);
        for (i, (view, _)) in views.iter().enumerate() {
            let eye = view.eye();
            let g = Globals {
                view_proj: view.view_proj().to_cols_array_2d(),
                tool_model: tool_model.to_cols_array_2d(),
                panel_model: panel_model.to_cols_array_2d(),
                eye: [eye.x, eye.y, eye.z, 1.0],
                light: LIGHT_DIR.normalize().extend(LIGHT_INTENSITY).to_array(),
                misc: [
                    1.0 / s.stress_max.max(1e-6),
                    if ids { 1.0 } else { 0.0 },
                    s.exposure,
                    0.0,
                ],
            };
            self.queue.write_buffer(
                &self.scene.globals,
                i as u64 * GLOBALS_STRIDE,
                bytemuck::bytes_of(&g),
            );
        }
        let att = self
            .attachments
            .as_ref()
            .expect("attachments were just made");
        let clear = if ids {
            wgpu::Color::BLACK
        } else {
            let [r, g, b] = s.background;
            wgpu::Color {
                r,
                g,
                b,
                a: s.background_alpha,
            }
        };
        let last = views.len().saturating_sub(1);
        for (i, (_, target)) in views.iter().enumerate() {
            let timestamp_writes = self.timer.as_ref().filter(|_| i == last).map(|t| {
                wgpu::RenderPassTimestampWrites {
                    query_set: &t.queries,
                    beginning_of_pass_write_index: None,
                    end_of_pass_write_index: Some(1),
                }
            });
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("view"),
                color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                    view: &att.colour,
                    depth_slice: None,
                    resolve_target: Some(target),
                    ops: wgpu::Operations {
                        load: wgpu::LoadOp::Clear(clear),
                        store: wgpu::StoreOp::Discard,
                    },
                })],
                depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                    view: &att.depth,
                    depth_ops: Some(wgpu::Operations {
                        load: wgpu::LoadOp::Clear(1.0),
                        store: wgpu::StoreOp::Discard,
                    }),
                    stencil_ops: None,
                }),
                timestamp_writes,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            let offset = (i as u64 * GLOBALS_STRIDE) as u32;
            pass.set_bind_group(0, &self.scene.bind_group, &[offset]);
            self.draw(&mut pass);
        }
        if let Some(t) = &self.timer {
            encoder.resolve_query_set(&t.queries, 0..2, &t.resolve, 0);
            encoder.copy_buffer_to_buffer(&t.resolve, 0, &t.read, 0, 16);
        }
    }

    fn draw(&self, pass: &mut wgpu::RenderPass<'_>) {
        let s = &self.settings;
        let sc = &self.scene;
        if s.overlays.stress {
            pass.set_pipeline(&self.pipelines.stress);
            pass.draw(0..sc.surface_faces.len * 3, 0..1);
        } else {
            if sc.skin_index.len > 0 {
                pass.set_pipeline(&self.pipelines.skin);
                pass.set_vertex_buffer(0, self.skin.positions.slice(..));
                pass.set_vertex_buffer(1, self.skin.normals.slice(..));
                pass.set_index_buffer(sc.skin_index.buffer.slice(..), wgpu::IndexFormat::Uint32);
                pass.draw_indexed(0..sc.skin_index.len, 0, 0..1);
            }
            if sc.cut_faces.len > 0 {
                pass.set_pipeline(&self.pipelines.cut);
                pass.draw(0..sc.cut_faces.len * 3, 0..1);
            }
        }
        if s.tool.transform.is_some() {
            pass.set_pipeline(&self.pipelines.tool);
            pass.set_vertex_buffer(0, self.tool.vertices.slice(..));
            pass.set_index_buffer(self.tool.indices.slice(..), wgpu::IndexFormat::Uint32);
            pass.draw_indexed(0..self.tool.index_count, 0, 0..1);
        }
        if sc.markers.len > 0 {
            pass.set_pipeline(&self.pipelines.markers);
            pass.set_vertex_buffer(0, self.sphere.vertices.slice(..));
            pass.set_vertex_buffer(1, sc.markers.buffer.slice(..));
            pass.set_index_buffer(self.sphere.indices.slice(..), wgpu::IndexFormat::Uint32);
            pass.draw_indexed(0..self.sphere.index_count, 0, 0..sc.markers.len);
        }
        if sc.lines.len > 0 {
            pass.set_pipeline(&self.pipelines.surface_line);
            pass.set_vertex_buffer(0, sc.lines.buffer.slice(..));
            pass.draw(0..sc.lines.len, 0..1);
        }
        // Blended, so after every opaque surface; the x-ray wireframe stays on top.
        if let (Some(_), Some(image)) = (s.panel, self.panel.bind_group()) {
            pass.set_pipeline(&self.pipelines.panel);
            pass.set_bind_group(1, image, &[]);
            pass.draw(0..6, 0..1);
        }
        if s.overlays.wireframe && sc.edges.len > 0 {
            pass.set_pipeline(&self.pipelines.wireframe);
            pass.draw(0..sc.edges.len * 2, 0..1);
        }
    }

    /// GPU time of the last submitted frame (skin pass start to last view's end), ms;
    /// `None` without timestamps. Waits for the device.
    pub fn last_gpu_ms(&self) -> Result<Option<f64>, RenderError> {
        let Some(t) = &self.timer else {
            return Ok(None);
        };
        let words = read_buffer(&self.device, &t.read)?;
        let q: &[u64] = bytemuck::cast_slice(&words);
        Ok(Some(
            q[1].wrapping_sub(q[0]) as f64 * t.period_ns as f64 * 1e-6,
        ))
    }

    /// The deformed skin vertex positions of the last submitted frame (read back from the
    /// device; for tests and tools). Waits for the device.
    pub fn read_skin_positions(&self) -> Result<Vec<Vec3>, RenderError> {
        let n = self.skin.vertex_count() as u64;
        let staging = self.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("skin readback"),
            size: (n * 16).max(16),
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let mut enc = self
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor::default());
        enc.copy_buffer_to_buffer(&self.skin.positions, 0, &staging, 0, n * 16);
        self.queue.submit([enc.finish()]);
        let bytes = read_buffer(&self.device, &staging)?;
        let v: &[[f32; 4]] = bytemuck::cast_slice(&bytes);
        Ok(v[..n as usize]
            .iter()
            .map(|p| Vec3::new(p[0], p[1], p[2]))
            .collect())
    }

    /// Number of skin triangles drawn (those of live tets) as of the last `prepare`.
    pub fn visible_skin_triangles(&self) -> u32 {
        self.scene.skin_index.len / 3
    }

    /// Number of cut-surface faces drawn as of the last `prepare`.
    pub fn cut_faces(&self) -> u32 {
        self.scene.cut_faces.len
    }
}

/// Map `buffer` (MAP_READ), wait, and copy its bytes out.
pub(crate) fn read_buffer(
    device: &wgpu::Device,
    buffer: &wgpu::Buffer,
) -> Result<Vec<u8>, RenderError> {
    buffer.slice(..).map_async(wgpu::MapMode::Read, |_| {});
    device
        .poll(wgpu::PollType::wait_indefinitely())
        .map_err(|e| RenderError::Readback(e.to_string()))?;
    let view = buffer
        .slice(..)
        .get_mapped_range()
        .map_err(|e| RenderError::Readback(e.to_string()))?;
    let out = view.to_vec();
    drop(view);
    buffer.unmap();
    Ok(out)
}
