//! The scene passes' bind group layouts and render pipelines (one set per sample count).

use super::scene_data::{BUBBLE_VERTEX_BYTES, OBJECT_VERTEX_BYTES, VIEW_BYTES};
use super::shader_source::scene_wgsl;
use super::water_data::WATER_UNIFORM_BYTES;

/// Colour format of the HDR targets (frame and cube faces): blendable and resolvable.
pub(super) const HDR_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba16Float;
/// Depth format; depth is `near / view depth`, larger nearer, cleared to 0.
pub(super) const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;

/// The three bind group layouts: view (dynamic offset), scene, bubble tables (LUTs, cube
/// maps and film fields).
#[derive(Debug)]
pub(super) struct Layouts {
    pub view: wgpu::BindGroupLayout,
    pub scene: wgpu::BindGroupLayout,
    pub bubble: wgpu::BindGroupLayout,
    /// The cube mip chain's compute passes (group 3: faces, chain, step).
    pub mip: wgpu::BindGroupLayout,
    /// Copies level 0 from the faces into the chain.
    pub mip_copy: wgpu::ComputePipeline,
    /// Box-filters one level into the next.
    pub mip_downsample: wgpu::ComputePipeline,
    /// Refills one level's borders from the neighbouring faces.
    pub mip_borders: wgpu::ComputePipeline,
    /// The water's (group 3, bindings 3..6): `Water` uniform, Fresnel tables, the cube
    /// map seen from the mirrored eye.
    pub water: wgpu::BindGroupLayout,
    opaque: wgpu::PipelineLayout,
    water_pass: wgpu::PipelineLayout,
    bubbles: wgpu::PipelineLayout,
    module: wgpu::ShaderModule,
}

fn entry(binding: u32, ty: wgpu::BindingType) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        // Compute too: the cube mip passes read the scene uniform.
        visibility: wgpu::ShaderStages::VERTEX
            | wgpu::ShaderStages::FRAGMENT
            | wgpu::ShaderStages::COMPUTE,
        ty,
        count: None,
    }
}

fn storage() -> wgpu::BindingType {
    wgpu::BindingType::Buffer {
        ty: wgpu::BufferBindingType::Storage { read_only: true },
        has_dynamic_offset: false,
        min_binding_size: None,
    }
}

fn texture(dimension: wgpu::TextureViewDimension) -> wgpu::BindingType {
    wgpu::BindingType::Texture {
        sample_type: wgpu::TextureSampleType::Float { filterable: false },
        view_dimension: dimension,
        multisampled: false,
    }
}

impl Layouts {
    pub(super) fn new(device: &wgpu::Device) -> Layouts {
        let layout = |label, entries: &[wgpu::BindGroupLayoutEntry]| {
            device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
                label: Some(label),
                entries,
            })
        };
        let view = layout(
            "view",
            &[entry(
                0,
                wgpu::BindingType::Buffer {
                    ty: wgpu::BufferBindingType::Uniform,
                    has_dynamic_offset: true,
                    min_binding_size: wgpu::BufferSize::new(VIEW_BYTES),
                },
            )],
        );
        let uniform = wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Uniform,
            has_dynamic_offset: false,
            min_binding_size: None,
        };
        let scene = layout(
            "scene",
            &[
                entry(0, uniform),
                entry(1, storage()),
                entry(2, storage()),
                // The image atlas (Rgba32Float, read with textureLoad).
                entry(3, texture(wgpu::TextureViewDimension::D2)),
            ],
        );
        let bubble = layout(
            "bubble tables",
            &[
                entry(0, texture(wgpu::TextureViewDimension::D2)),
                entry(1, storage()),
                entry(2, texture(wgpu::TextureViewDimension::D2Array)),
                entry(3, storage()),
                // The film fields' bordered texels (Rg32Float, read with textureLoad).
                entry(4, texture(wgpu::TextureViewDimension::D2)),
            ],
        );
        let compute = |binding, ty| wgpu::BindGroupLayoutEntry {
            binding,
            visibility: wgpu::ShaderStages::COMPUTE,
            ty,
            count: None,
        };
        let mip = layout(
            "cube mips",
            &[
                compute(0, texture(wgpu::TextureViewDimension::D2Array)),
                compute(
                    1,
                    wgpu::BindingType::Buffer {
                        ty: wgpu::BufferBindingType::Storage { read_only: false },
                        has_dynamic_offset: false,
                        min_binding_size: None,
                    },
                ),
                compute(2, uniform),
                // `CubeMap::border_source_table`: which texel each border texel copies.
                compute(6, storage()),
            ],
        );
        let water = layout(
            "water",
            &[
                entry(
                    3,
                    wgpu::BindingType::Buffer {
                        ty: wgpu::BufferBindingType::Uniform,
                        has_dynamic_offset: false,
                        min_binding_size: wgpu::BufferSize::new(WATER_UNIFORM_BYTES),
                    },
                ),
                entry(4, storage()),
                entry(5, texture(wgpu::TextureViewDimension::D2Array)),
            ],
        );
        let pipeline_layout = |groups: &[Option<&wgpu::BindGroupLayout>]| {
            device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
                label: None,
                bind_group_layouts: groups,
                immediate_size: 0,
            })
        };
        let opaque = pipeline_layout(&[Some(&view), Some(&scene)]);
        let water_pass = pipeline_layout(&[Some(&view), Some(&scene), None, Some(&water)]);
        let bubbles = pipeline_layout(&[Some(&view), Some(&scene), Some(&bubble)]);
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("scene"),
            source: wgpu::ShaderSource::Wgsl(scene_wgsl().into()),
        });
        let mips = pipeline_layout(&[None, Some(&scene), None, Some(&mip)]);
        let compute_pipeline = |entry| {
            device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                label: Some(entry),
                layout: Some(&mips),
                module: &module,
                entry_point: Some(entry),
                compilation_options: Default::default(),
                cache: None,
            })
        };
        Layouts {
            view,
            scene,
            bubble,
            mip_copy: compute_pipeline("cs_mip_copy"),
            mip_downsample: compute_pipeline("cs_mip_downsample"),
            mip_borders: compute_pipeline("cs_mip_borders"),
            mip,
            water,
            opaque,
            water_pass,
            bubbles,
            module,
        }
    }
}

/// The pipelines of one sample count.
#[derive(Debug)]
pub(super) struct Pipelines {
    pub samples: u32,
    pub sky: wgpu::RenderPipeline,
    pub ground: wgpu::RenderPipeline,
    pub objects: wgpu::RenderPipeline,
    /// The water's triangles (object vertices), shaded by `fs_water`.
    pub water: wgpu::RenderPipeline,
    /// Bubble film, blended (Zero, OneMinusSrc): `dest ← dest ⊙ T`.
    pub transmit: wgpu::RenderPipeline,
    /// Bubble film, blended (One, One): `dest ← dest + R ⊙ env + highlights`.
    pub add: wgpu::RenderPipeline,
}

/// One pass's fixed functions.
struct Desc<'a> {
    label: &'a str,
    vertex: &'a str,
    fragment: &'a str,
    buffers: &'a [Option<wgpu::VertexBufferLayout<'a>>],
    depth_write: bool,
    depth_compare: wgpu::CompareFunction,
    blend: Option<wgpu::BlendState>,
}

/// `src·a + dst·b` on colour; alpha keeps its value.
fn blend(src: wgpu::BlendFactor, dst: wgpu::BlendFactor) -> wgpu::BlendState {
    wgpu::BlendState {
        color: wgpu::BlendComponent {
            src_factor: src,
            dst_factor: dst,
            operation: wgpu::BlendOperation::Add,
        },
        alpha: wgpu::BlendComponent {
            src_factor: wgpu::BlendFactor::Zero,
            dst_factor: wgpu::BlendFactor::One,
            operation: wgpu::BlendOperation::Add,
        },
    }
}

/// The multiplicative pass's blend: seed 000's `GL_ZERO, GL_ONE_MINUS_SRC_COLOR`.
pub(super) fn transmit_blend() -> wgpu::BlendState {
    blend(wgpu::BlendFactor::Zero, wgpu::BlendFactor::OneMinusSrc)
}

/// The additive passes' blend.
pub(super) fn add_blend() -> wgpu::BlendState {
    blend(wgpu::BlendFactor::One, wgpu::BlendFactor::One)
}

impl Pipelines {
    pub(super) fn new(device: &wgpu::Device, layouts: &Layouts, samples: u32) -> Pipelines {
        let object_attrs = wgpu::vertex_attr_array![
            0 => Float32x3, 1 => Float32x3, 2 => Uint32, 3 => Float32x2
        ];
        let objects = [Some(wgpu::VertexBufferLayout {
            array_stride: OBJECT_VERTEX_BYTES,
            step_mode: wgpu::VertexStepMode::Vertex,
            attributes: &object_attrs,
        })];
        let ground_attrs = wgpu::vertex_attr_array![0 => Float32x3];
        let ground = [Some(wgpu::VertexBufferLayout {
            array_stride: 12,
            step_mode: wgpu::VertexStepMode::Vertex,
            attributes: &ground_attrs,
        })];
        let bubble_attrs = wgpu::vertex_attr_array![
            0 => Float32x3, 1 => Float32x3, 2 => Float32, 3 => Float32, 4 => Uint32,
            5 => Float32x3, 6 => Uint32x2, 7 => Float32x3
        ];
        let bubbles = [Some(wgpu::VertexBufferLayout {
            array_stride: BUBBLE_VERTEX_BYTES,
            step_mode: wgpu::VertexStepMode::Vertex,
            attributes: &bubble_attrs,
        })];
        let make = |d: Desc<'_>, layout: &wgpu::PipelineLayout| {
            device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some(d.label),
                layout: Some(layout),
                vertex: wgpu::VertexState {
                    module: &layouts.module,
                    entry_point: Some(d.vertex),
                    compilation_options: Default::default(),
                    buffers: d.buffers,
                },
                primitive: wgpu::PrimitiveState::default(),
                depth_stencil: Some(wgpu::DepthStencilState {
                    format: DEPTH_FORMAT,
                    depth_write_enabled: Some(d.depth_write),
                    depth_compare: Some(d.depth_compare),
                    stencil: Default::default(),
                    bias: Default::default(),
                }),
                multisample: wgpu::MultisampleState {
                    count: samples,
                    ..Default::default()
                },
                fragment: Some(wgpu::FragmentState {
                    module: &layouts.module,
                    entry_point: Some(d.fragment),
                    compilation_options: Default::default(),
                    targets: &[Some(wgpu::ColorTargetState {
                        format: HDR_FORMAT,
                        blend: d.blend,
                        write_mask: wgpu::ColorWrites::ALL,
                    })],
                }),
                multiview_mask: None,
                cache: None,
            })
        };
        use wgpu::CompareFunction::{Always, Greater};
        let opaque = |label, vertex, fragment, buffers, compare| {
            let d = Desc {
                label,
                vertex,
                fragment,
                buffers,
                depth_write: compare == Greater,
                depth_compare: compare,
                blend: None,
            };
            make(d, &layouts.opaque)
        };
        let film = |label, fragment, blend| {
            let d = Desc {
                label,
                vertex: "vs_bubble",
                fragment,
                buffers: &bubbles,
                depth_write: false,
                depth_compare: Greater,
                blend: Some(blend),
            };
            make(d, &layouts.bubbles)
        };
        Pipelines {
            samples,
            sky: opaque("sky", "vs_sky", "fs_sky", &[], Always),
            ground: opaque("ground", "vs_ground", "fs_ground", &ground, Greater),
            objects: opaque("objects", "vs_object", "fs_object", &objects, Greater),
            water: make(
                Desc {
                    label: "water",
                    vertex: "vs_water",
                    fragment: "fs_water",
                    buffers: &objects,
                    depth_write: true,
                    depth_compare: Greater,
                    blend: None,
                },
                &layouts.water_pass,
            ),
            transmit: film("bubble transmit", "fs_bubble_transmit", transmit_blend()),
            add: film("bubble add", "fs_bubble_add", add_blend()),
        }
    }
}
